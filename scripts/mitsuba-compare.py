#!/usr/bin/env python3
"""Path tracers at equal time: hikari's `path` against Mitsuba 3's `path`
on the same scene, 2 cores (issue #11, item 6).

The scene is read from hikari's TOML and written as a Mitsuba scene dict
(quads, boxes, diffuse materials, point lights: enough for cornell-box, the
Mitsuba Cornell box with a point light under the ceiling). Each renderer is
measured against its own long reference, made of two independent halves so
that the reference's own noise can be subtracted:

    E|a - ref|^2 = E|a - truth|^2 + E|ref - truth|^2,
    E|ref - truth|^2 ~ |half1 - half2|^2 / 4 (per pixel, summed),

and the error is the project's metric (shared/relerr.py --halves): the
per-pixel RMS error over the reference's mean.
The two references are also compared with each other: two independent
renderers agreeing on the same scene.

Mitsuba is not a dependency of hikari; this is a benchmark script:

    apt-get install libllvm19   # for the llvm_* variants
    python3 -m venv /tmp/mts && /tmp/mts/bin/pip install mitsuba numpy
    cargo build --release
    /tmp/mts/bin/python scripts/mitsuba-compare.py --time 80 --size 256
"""
import argparse
import math
import os
import subprocess
import sys
import time
import tomllib

import mitsuba as mi
import numpy as np

# MITSUBA_VARIANT=scalar_rgb for the one-sample-at-a-time CPU variant;
# llvm_ad_rgb (the default here) is Mitsuba's fastest on a CPU: wavefront,
# JIT-compiled to vector code by LLVM (Debian's libllvm19).
mi.set_variant(os.environ.get("MITSUBA_VARIANT", "llvm_ad_rgb"))
T = mi.ScalarTransform4f
# MITSUBA_SAMPLER=multijitter (or stratified, orthogonal, ldsampler) for
# Mitsuba's stratified samplers; independent, its default, otherwise.
SAMPLER = os.environ.get("MITSUBA_SAMPLER", "independent")


def mitsuba_scene(toml_path, size, rfilter):
    """hikari's scene file as a Mitsuba scene dict (the subset cornell-box uses)."""
    with open(toml_path, "rb") as f:
        desc = tomllib.load(f)
    cam = desc["camera"]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1},
        "sensor": {
            "type": "perspective",
            "fov": cam["fov_y"],
            "fov_axis": "y",
            "to_world": T().look_at(origin=cam["position"], target=cam["look_at"], up=cam["up"]),
            "sampler": {"type": SAMPLER},
            "film": {
                "type": "hdrfilm",
                "width": size,
                "height": size,
                "rfilter": {"type": rfilter},
                "pixel_format": "rgb",
                "component_format": "float32",
            },
        },
    }
    # hikari's diffuse surfaces reflect on both sides; Mitsuba's on the front only.
    for m in desc["material"]:
        if m["type"] != "diffuse":
            sys.exit(f"{toml_path}: material {m['name']}: only diffuse is translated")
        scene[m["name"]] = {
            "type": "twosided",
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["albedo"]}},
        }
    for i, o in enumerate(desc["object"]):
        bsdf = {"type": "ref", "id": o["material"]}
        if o.get("shape") == "quad":
            c, u, v = (np.array(o[k], dtype=float) for k in ("corner", "edge_u", "edge_v"))
            n = np.cross(u, v)
            n /= np.linalg.norm(n)
            centre = c + (u + v) / 2
            m = np.identity(4)
            m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, centre
            scene[f"object{i}"] = {"type": "rectangle", "to_world": T(m.tolist()), "bsdf": bsdf}
        elif o.get("shape") == "box":
            to_world = (
                T()
                .translate(o["center"])
                .rotate([0, 1, 0], o.get("rotate_y", 0.0))
                .scale([s / 2 for s in o["size"]])
            )
            scene[f"object{i}"] = {"type": "cube", "to_world": to_world, "bsdf": bsdf}
        else:
            sys.exit(f"{toml_path}: object {i}: only quads and boxes are translated")
    for i, light in enumerate(desc["light"]):
        if light["type"] != "point":
            sys.exit(f"{toml_path}: light {i}: only point lights are translated")
        scene[f"light{i}"] = {
            "type": "point",
            "position": light["position"],
            "intensity": {"type": "rgb", "value": light["intensity"]},
        }
    return mi.load_dict(scene)


class Mitsuba:
    def __init__(self, toml_path, size, rfilter):
        self.scene = mitsuba_scene(toml_path, size, rfilter)
        self.name = f"Mitsuba 3 {mi.__version__} {mi.variant()} path ({rfilter} filter, {SAMPLER} sampler)"

    def render(self, spp, seed):
        start = time.perf_counter()
        image = np.array(mi.render(self.scene, spp=spp, seed=seed), dtype=np.float64)
        return image[:, :, :3], time.perf_counter() - start


class Hikari:
    def __init__(self, binary, toml_path, size, out_dir):
        self.binary, self.toml_path, self.size, self.out = binary, toml_path, size, out_dir
        self.name = "hikari path (box filter)"

    def render(self, spp, seed):
        out = os.path.join(self.out, f"hikari-{spp}-{seed}.exr")
        start = time.perf_counter()
        subprocess.run(
            [self.binary, "render", self.toml_path, "--renderer", "path", "--resolution", f"{self.size}x{self.size}",
             "--spp", str(spp), "--seed", str(seed), "-q", "-o", out],
            check=True,
        )
        seconds = time.perf_counter() - start
        image = np.array(mi.Bitmap(out), dtype=np.float64)[:, :, :3]
        os.remove(out)
        return image, seconds


def squared_norm(image):
    return float(np.sum(image * image))


class Reference:
    """The mean of two independent halves and its own squared error (summed)."""

    def __init__(self, renderer, spp, seeds):
        (a, ta), (b, tb) = (renderer.render(spp // 2, s) for s in seeds)
        self.image = (a + b) / 2
        self.noise = squared_norm(a - b) / 4
        self.seconds = ta + tb

    def relative_rmse(self, image):
        """The project's metric (shared/relerr.py --halves): per-pixel RMS
        error over the reference's mean, the reference's own noise removed."""
        measured = squared_norm(image - self.image)
        return math.sqrt(max(measured - self.noise, 0.0) / image.size) / self.image.mean()

    def raw_relative_rmse(self, image):
        return math.sqrt(squared_norm(image - self.image) / image.size) / self.image.mean()


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scene", default=os.path.join(root, "scenes", "cornell-box.toml"))
    p.add_argument("--hikari", default=os.path.join(root, "target", "release", "hikari"))
    p.add_argument("--size", type=int, default=256)
    p.add_argument("--time", type=float, default=80.0, help="equal-time budget, seconds")
    p.add_argument("--ref-spp", type=int, default=8192, help="reference samples per pixel (two halves)")
    p.add_argument("--filters", default="box,gaussian", help="Mitsuba reconstruction filters to measure")
    p.add_argument("--out", default=os.path.join(root, "target", "mitsuba-compare"))
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)

    renderers = [Hikari(args.hikari, args.scene, args.size, args.out)]
    renderers += [Mitsuba(args.scene, args.size, f) for f in args.filters.split(",") if f]
    references = {}
    print(f"{args.scene} at {args.size}x{args.size}, {os.cpu_count()} cores, budget {args.time:g} s")
    print(f"| renderer | spp | seconds | relative RMSE | at {args.time:g} s (x sqrt(seconds / {args.time:g})) "
          "| raw (reference noise included) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for r in renderers:
        ref = Reference(r, args.ref_spp, (1001, 2002))
        references[r.name] = ref
        print(f"# {r.name}: reference {args.ref_spp} spp in {ref.seconds:.1f} s, "
              f"its own relative RMSE {math.sqrt(ref.noise / ref.image.size) / ref.image.mean():.4f}", file=sys.stderr)
        # Samples per second from the reference, then one run sized to the
        # budget; its error is also scaled to the budget exactly (variance
        # falls as 1/time for an unbiased renderer).
        spp = max(1, round(args.time * args.ref_spp / ref.seconds))
        image, seconds = r.render(spp, 42)
        error = ref.relative_rmse(image)
        print(f"| {r.name} | {spp} | {seconds:.1f} | {error:.4f} | {error * math.sqrt(seconds / args.time):.4f} "
              f"| {ref.raw_relative_rmse(image):.4f} |", flush=True)
    names = list(references)
    for other in names[1:]:
        a, b = references[names[0]], references[other]
        print(f"# references: {names[0]} against {other}: relative RMSE {b.raw_relative_rmse(a.image):.4f}, "
              f"mean ratio {a.image.mean() / b.image.mean():.4f}")


if __name__ == "__main__":
    main()
