use super::*;
use crate::progressive::ImageMean;

fn header(shard: u32, shards: u32, total: u32) -> PartHeader {
    PartHeader {
        renderer: "path".into(),
        scene: "cornell-box".into(),
        scene_hash: fingerprint(b"scene"),
        settings: BTreeMap::from([("seed".to_string(), "0".to_string())]),
        width: 2,
        height: 1,
        total_passes: Some(total),
        shard,
        shards,
        passes: Shard { index: shard, count: shards }.passes(total).collect(),
        stopped_early: false,
        time_limited: false,
    }
}

/// Pass i's image: pixel 0 is i, pixel 1 is 1/i (values whose sums round).
fn pass_image(i: u32) -> [[f64; 3]; 2] {
    let a = i as f32;
    let b = 1.0 / i as f32;
    [[a as f64; 3], [b as f64; 3]]
}

fn part(shard: u32, shards: u32, total: u32) -> Part {
    let header = header(shard, shards, total);
    let mut sums = vec![[0.0; 3]; 2];
    for &i in &header.passes {
        for (s, p) in sums.iter_mut().zip(pass_image(i)) {
            for c in 0..3 {
                s[c] += p[c];
            }
        }
    }
    Part { header, sums }
}

fn named(parts: Vec<Part>) -> Vec<(String, Part)> {
    parts.into_iter().map(|p| (format!("part-{}.exr", p.header.shard), p)).collect()
}

fn single_run(total: u32) -> Image {
    let mut mean = ImageMean::new(2, 1);
    for i in 1..=total {
        let mut image = Image::new(2, 1);
        for (px, p) in image.pixels.iter_mut().zip(pass_image(i)) {
            *px = glam::Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        }
        mean.add(&image);
    }
    mean.mean()
}

#[test]
fn shards_interleave_the_passes() {
    let s = Shard::parse("2/3").unwrap();
    assert_eq!(s.passes(7).collect::<Vec<_>>(), [2, 5]);
    assert_eq!(Shard::parse("3/3").unwrap().passes(7).collect::<Vec<_>>(), [3, 6]);
    assert_eq!(Shard::parse("1/1").unwrap().passes(3).collect::<Vec<_>>(), [1, 2, 3]);
    for (k, m, n) in [(1, 3, 7), (3, 3, 7), (2, 2, 7), (7, 7, 7), (5, 9, 4), (1, 1, 1)] {
        let s = Shard { index: k, count: m };
        assert_eq!(s.len(n) as usize, s.passes(n).count(), "{k}/{m} of {n}");
    }
    for bad in ["0/3", "4/3", "3", "a/b", "1/0", ""] {
        assert!(Shard::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn merged_parts_equal_the_single_run_bit_for_bit() {
    for shards in [1, 2, 3, 7] {
        let parts = named((1..=shards).rev().map(|k| part(k, shards, 7)).collect());
        let merged = merge(&parts).unwrap();
        assert_eq!(merged.passes, 7);
        assert_eq!(merged.image.pixels, single_run(7).pixels, "{shards} shards");
    }
}

#[test]
fn parts_are_written_and_read_back_exactly() {
    let dir = std::env::temp_dir().join(format!("hikari-shard-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("part-2.exr");
    let mut p = part(2, 3, 7);
    p.sums[1][2] = 1.0 / 3.0; // a value with all 53 bits
    p.write(&path).unwrap();
    let back = Part::read(&path).unwrap();
    assert_eq!(back.header, p.header);
    assert_eq!(back.sums, p.sums);
    // An ordinary EXR reader sees the part's own mean.
    let mean = crate::output::read_exr(&path).unwrap();
    assert_eq!(mean.pixels, p.mean().pixels);
    // No temporary file is left beside it.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    // A truncated part is an error, not a panic.
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    assert!(Part::read(&path).is_err());
    // An image that is not a part says so.
    crate::output::write_image(&path, &p.mean(), 0.0).unwrap();
    assert!(Part::read(&path).unwrap_err().contains("--shard"));
    std::fs::remove_dir_all(&dir).unwrap();
}

fn merge_error(parts: Vec<Part>) -> String {
    merge(&named(parts)).unwrap_err()
}

#[test]
fn parts_that_do_not_belong_together_are_refused_by_name() {
    let mut other_scene = part(2, 3, 7);
    other_scene.header.scene_hash = fingerprint(b"another scene");
    let e = merge_error(vec![part(1, 3, 7), other_scene, part(3, 3, 7)]);
    assert!(e.starts_with("part-2.exr: scene content"), "{e}");

    let mut other_seed = part(3, 3, 7);
    other_seed.header.settings.insert("seed".into(), "1".into());
    let e = merge_error(vec![part(1, 3, 7), part(2, 3, 7), other_seed]);
    assert!(e.starts_with("part-3.exr: setting seed"), "{e}");

    let mut other_renderer = part(2, 3, 7);
    other_renderer.header.renderer = "vcm".into();
    assert!(merge_error(vec![part(1, 3, 7), other_renderer]).contains("renderer"));

    let e = merge_error(vec![part(1, 3, 7), part(2, 3, 8), part(3, 3, 7)]);
    assert!(e.contains("total passes"), "{e}");
    let e = merge_error(vec![part(1, 3, 7), part(2, 2, 7)]);
    assert!(e.contains("shard count"), "{e}");
}

#[test]
fn missing_and_duplicated_passes_are_refused() {
    let e = merge_error(vec![part(1, 4, 7), part(3, 4, 7)]);
    assert!(e.contains("shards 2/4, 4/4 missing"), "{e}");
    let parts = vec![("a.exr".to_string(), part(2, 3, 7)), ("b.exr".to_string(), part(2, 3, 7))];
    let e = merge(&parts).unwrap_err();
    assert!(e.contains("b.exr and a.exr are both shard 2/3"), "{e}");
    // A part whose passes are not its shard's (a pass dropped or added).
    let mut wrong = part(2, 3, 7);
    wrong.header.passes = vec![2];
    let e = merge_error(vec![part(1, 3, 7), wrong, part(3, 3, 7)]);
    assert!(e.starts_with("part-2.exr: holds passes [2]"), "{e}");
}

#[test]
fn parts_stopped_early_merge_what_they_did() {
    let mut early = part(2, 3, 7);
    early.header.passes = vec![2];
    early.header.stopped_early = true;
    early.sums = vec![pass_image(2)[0], pass_image(2)[1]];
    // Interrupted (no time limit): the set lacks pass 5.
    let e = merge_error(vec![part(1, 3, 7), early.clone(), part(3, 3, 7)]);
    assert!(e.starts_with("part-2.exr: shard 2/3 stopped after passes [2] of [2, 5]"), "{e}");
    early.header.time_limited = true;
    let merged = merge(&named(vec![part(1, 3, 7), early, part(3, 3, 7)])).unwrap();
    assert_eq!(merged.passes, 6);
    assert_eq!(merged.header.passes, [1, 2, 3, 4, 6, 7]);
    // pixel 0: (1 + 4 + 7 + 2 + 3 + 6) / 6
    assert_eq!(merged.image.pixels[0].x, 23.0 / 6.0);
}
