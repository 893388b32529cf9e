"""Time ratios between two `hikari bench` outputs (scripts/bench-compare.sh).

Row lines: `LABEL at WxH: F fps (T ms/frame), ...`; tracing lines:
`    SCENE, N paths: CPU a, GPU b (maps left on the GPU), GPU c (maps read back)`
in million paths per second, compared through their inverse. Prints the
rows both outputs have, the worst ratio first, and the geometric mean.
"""

import math
import re
import sys

ROW = re.compile(r"^(?P<label>\S.*?) at (?P<size>\d+x\d+): [\d.]+ fps \((?P<ms>[\d.]+) ms/frame\)")
TRACE = re.compile(r"^\s+(?P<label>.+?, \d+ paths): CPU (?P<cpu>[\d.]+), GPU (?P<gpu>[\d.]+) \(maps left on the GPU\), GPU (?P<back>[\d.]+)")


def times(path):
    """Label -> (value, unit) where a larger value is slower."""
    rows = {}
    for line in open(path, encoding="utf-8"):
        m = ROW.match(line)
        if m:
            rows[f"{m['label']} at {m['size']}"] = (float(m["ms"]), "ms")
            continue
        m = TRACE.match(line)
        if m:
            for key, name in (("cpu", "CPU tracing"), ("gpu", "GPU tracing"), ("back", "GPU tracing + readback")):
                rows[f"{name}, {m['label']}"] = (1.0 / float(m[key]), "s/M paths")
    return rows


def main():
    before, after = times(sys.argv[1]), times(sys.argv[2])
    rev = sys.argv[3] if len(sys.argv) > 3 else "before"
    common = [k for k in before if k in after]
    if not common:
        sys.exit("no row appears in both outputs")
    ratios = sorted(((after[k][0] / before[k][0], k) for k in common), reverse=True)
    print(f"\n| row | {rev} | now | now / {rev} |\n|---|---|---|---|")
    for ratio, k in ratios:
        (b, unit), (a, _) = before[k], after[k]
        if unit == "ms":
            print(f"| {k} | {b:.1f} ms | {a:.1f} ms | {ratio:.2f}x |")
        else:
            print(f"| {k} | {1 / b:.2f} M/s | {1 / a:.2f} M/s | {ratio:.2f}x |")
    mean = math.exp(sum(math.log(r) for r, _ in ratios) / len(ratios))
    print(f"\ngeometric mean of {len(ratios)} time ratios: {mean:.3f}x; worst {ratios[0][0]:.2f}x")
    for k in before.keys() - after.keys():
        print(f"only in {rev}: {k}")
    for k in after.keys() - before.keys():
        print(f"only now: {k}")


if __name__ == "__main__":
    main()
