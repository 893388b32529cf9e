//! Shards of one progressive render (#20): pass i depends on nothing but
//! the seed's stream i and the schedule's radius r_i, so M processes (the
//! machines of a cluster) can render passes K, K + M, K + 2M, … each
//! (`--shard K/M`) and a merge can add their sums into the image one run of
//! all N passes makes.
//!
//! A part is an EXR file: its own mean as the usual R, G, B (any viewer
//! shows it), its per-pixel sums as f64 bit patterns in pairs of 32-bit
//! integer channels (`sum.R.hi`, `sum.R.lo`, …: EXR has no 64-bit floats,
//! and the f32 mean would lose the last bits of the sums), and a
//! [`PartHeader`] in the header as TOML text (attribute `hikari.part`).
//! The merge checks that the parts belong together (same scene content,
//! settings, renderer, size and N; no pass missing or twice) and writes the
//! sums' mean. Sums of f32 pass values in f64 are exact while the values
//! span fewer than about 2⁵³⁻²⁴ = 2²⁹ of their own spacing, so the order of
//! the additions does not change them: the merged image is then
//! bit-identical to the single run's.

use super::mean_of_sums;
use crate::render::Image;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// `--shard K/M`: the K-th of M interleaved shares of the passes (K from 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    /// The whole render (1/1).
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Parses "K/M" with 1 ≤ K ≤ M.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || format!("{text}: a shard is K/M with 1 ≤ K ≤ M (e.g. 2/4: the second of four)");
        let (k, m) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) = (k.trim().parse::<u32>().map_err(|_| bad())?, m.trim().parse::<u32>().map_err(|_| bad())?);
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// This shard's passes among 1..=`total`: K, K + M, K + 2M, …
    pub fn passes(self, total: u32) -> impl Iterator<Item = u32> {
        (self.index..=total).step_by(self.count as usize)
    }

    /// How many of 1..=`total` are this shard's.
    pub fn len(self, total: u32) -> u32 {
        if self.index > total { 0 } else { (total - self.index) / self.count + 1 }
    }
}

/// What a part says about itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartHeader {
    /// The renderer that rendered the passes (`gpu` that fell back to the
    /// CPU says `photon-cpu`: the two are twins, not bit-identical).
    pub renderer: String,
    /// The scene as given on the command line (for messages only).
    pub scene: String,
    /// FNV-1a 64 of the scene file's bytes (or the built-in scene's text).
    pub scene_hash: String,
    /// Every setting that changes the image, by name.
    pub settings: BTreeMap<String, String>,
    pub width: u32,
    pub height: u32,
    /// N, the passes of the whole render; None where the shards were
    /// open-ended (`--time` without `--passes`).
    pub total_passes: Option<u32>,
    pub shard: u32,
    pub shards: u32,
    /// The passes this part rendered, in order.
    pub passes: Vec<u32>,
    /// Whether the part stopped before its last pass (`--time`, Ctrl-C):
    /// its passes are a prefix of its shard's.
    pub stopped_early: bool,
    /// Whether it had a time limit (`--time`): only then is stopping early
    /// what was asked for; otherwise (Ctrl-C) the set is incomplete.
    #[serde(default)]
    pub time_limited: bool,
}

/// A part: its header and its per-pixel sums over its passes.
#[derive(Clone, Debug)]
pub struct Part {
    pub header: PartHeader,
    pub sums: Vec<[f64; 3]>,
}

/// FNV-1a, 64 bits: a stable fingerprint of a scene's bytes (not a
/// defence against forgery, only against mixing up files).
pub fn fingerprint(bytes: &[u8]) -> String {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        hash ^= b as u64;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{hash:016x}")
}

const HEADER_ATTRIBUTE: &str = "hikari.part";
const CHANNELS: [&str; 3] = ["R", "G", "B"];

impl Part {
    /// The part's own mean (black where it has no passes).
    pub fn mean(&self) -> Image {
        mean_of_sums(self.header.width, self.header.height, &self.sums, self.header.passes.len() as u32)
    }

    /// Writes the part to `path` (an `.exr`) atomically: a temporary
    /// name, then a rename, so a shard that dies leaves no part behind.
    pub fn write(&self, path: &Path) -> Result<(), String> {
        use exr::prelude::*;
        let h = &self.header;
        let (w, ht) = (h.width as usize, h.height as usize);
        let mean = self.mean();
        let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
        for (c, name) in CHANNELS.iter().enumerate() {
            channels.push(AnyChannel::new(*name, FlatSamples::F32(mean.pixels.iter().map(|p| p[c]).collect())));
            let bits: Vec<u64> = self.sums.iter().map(|s| s[c].to_bits()).collect();
            let hi = bits.iter().map(|b| (b >> 32) as u32).collect();
            let lo = bits.iter().map(|b| *b as u32).collect();
            channels.push(AnyChannel::new(format!("sum.{name}.hi").as_str(), FlatSamples::U32(hi)));
            channels.push(AnyChannel::new(format!("sum.{name}.lo").as_str(), FlatSamples::U32(lo)));
        }
        let text = toml::to_string(h).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut attributes = LayerAttributes::default();
        attributes.other.insert(Text::from(HEADER_ATTRIBUTE), AttributeValue::Text(Text::from(text.as_str())));
        let layer = Layer::new((w, ht), attributes, Encoding::FAST_LOSSLESS, AnyChannels::sort(channels));
        let image = exr::image::Image::from_layer(layer);
        crate::output::atomically(path, |tmp| image.write().to_file(tmp).map_err(|e| e.to_string()))
    }

    /// Reads a part written by [`Part::write`]; errors say what is wrong
    /// with the file (not a part, truncated, inconsistent).
    pub fn read(path: &Path) -> Result<Part, String> {
        use exr::prelude::*;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .map_err(|e| format!("not a readable EXR file ({e})"))?;
        let layer = &image.layer_data;
        let text = match layer.attributes.other.get(&Text::from(HEADER_ATTRIBUTE)) {
            Some(AttributeValue::Text(t)) => t.to_string(),
            _ => {
                return Err(
                    "not a shard of a hikari render (no `hikari.part` header: render it with --shard K/M)".into()
                );
            }
        };
        let header: PartHeader = toml::from_str(&text)
            .map_err(|e| format!("its part header is damaged or from another version of hikari: {e}"))?;
        let pixels = (header.width as usize) * (header.height as usize);
        let size = layer.size;
        if (size.width(), size.height()) != (header.width as usize, header.height as usize) {
            return Err(format!("its header says {}x{} but it is {}x{}", header.width, header.height, size.0, size.1));
        }
        let channel = |name: &str| -> std::result::Result<&Vec<u32>, String> {
            let found = layer.channel_data.list.iter().find(|c| c.name.eq(name));
            match found.map(|c| &c.sample_data) {
                Some(FlatSamples::U32(v)) if v.len() == pixels => Ok(v),
                _ => Err(format!("channel {name} is missing or not 32-bit integers")),
            }
        };
        let mut sums = vec![[0.0f64; 3]; pixels];
        for (c, name) in CHANNELS.iter().enumerate() {
            let (hi, lo) = (channel(&format!("sum.{name}.hi"))?, channel(&format!("sum.{name}.lo"))?);
            for (s, (h, l)) in sums.iter_mut().zip(hi.iter().zip(lo)) {
                s[c] = f64::from_bits(((*h as u64) << 32) | *l as u64);
            }
        }
        if sums.iter().flatten().any(|v| !v.is_finite()) {
            return Err("its sums are not finite".into());
        }
        Ok(Part { header, sums })
    }
}

/// What a merge made: the image and how many passes it holds.
#[derive(Debug)]
pub struct Merged {
    pub image: Image,
    pub passes: u32,
    pub header: PartHeader,
}

/// Merges `parts` (each named by its file) into the mean of all their
/// passes, after checking that they belong together and, unless a part
/// stopped early, that they hold every pass 1..=N once. Errors name the
/// file at fault and what is wrong or missing.
pub fn merge(parts: &[(String, Part)]) -> Result<Merged, String> {
    let Some((first_name, first)) = parts.first() else { return Err("no parts to merge".into()) };
    let f = &first.header;
    for (name, part) in &parts[1..] {
        let h = &part.header;
        let differs = |what: &str, a: &dyn std::fmt::Debug, b: &dyn std::fmt::Debug| {
            format!("{name}: {what} {b:?}, but {first_name} has {a:?}: the parts are not of one render")
        };
        if h.scene_hash != f.scene_hash {
            return Err(differs("scene content (fingerprint)", &f.scene_hash, &h.scene_hash));
        }
        if h.renderer != f.renderer {
            return Err(differs("renderer", &f.renderer, &h.renderer));
        }
        if (h.width, h.height) != (f.width, f.height) {
            return Err(differs("size", &(f.width, f.height), &(h.width, h.height)));
        }
        for key in f.settings.keys().chain(h.settings.keys()) {
            if f.settings.get(key) != h.settings.get(key) {
                return Err(differs(&format!("setting {key}"), &f.settings.get(key), &h.settings.get(key)));
            }
        }
        if h.total_passes != f.total_passes {
            return Err(differs("total passes (--passes)", &f.total_passes, &h.total_passes));
        }
        if h.shards != f.shards {
            return Err(differs("shard count (--shard K/M)", &f.shards, &h.shards));
        }
    }
    // Each part's passes must be its shard's (all of them, or a prefix if it stopped early).
    let total = f.total_passes;
    for (name, part) in parts {
        let h = &part.header;
        let shard = Shard { index: h.shard, count: h.shards };
        if h.shard == 0 || h.shard > h.shards || h.shards == 0 {
            return Err(format!("{name}: shard {}/{} is not a shard", h.shard, h.shards));
        }
        let expected: Vec<u32> = match total {
            Some(n) => shard.passes(n).collect(),
            None => shard.passes(h.passes.last().copied().unwrap_or(0)).collect(),
        };
        let fits = if h.stopped_early { expected.starts_with(&h.passes) } else { expected == h.passes };
        if h.stopped_early && !h.time_limited && fits {
            return Err(format!(
                "{name}: shard {}/{} stopped after passes {:?} of {:?} (interrupted): render it again",
                h.shard, h.shards, h.passes, expected
            ));
        }
        if !fits {
            return Err(format!(
                "{name}: holds passes {:?}, which are not shard {}/{}'s{}",
                h.passes,
                h.shard,
                h.shards,
                total.map_or(String::new(), |n| format!(" of {n}"))
            ));
        }
        if part.sums.len() != (f.width * f.height) as usize {
            return Err(format!("{name}: {} pixels of sums for a {}x{} image", part.sums.len(), f.width, f.height));
        }
    }
    let mut owner: BTreeMap<u32, &str> = BTreeMap::new();
    for (name, part) in parts {
        if let Some(other) = owner.insert(part.header.shard, name) {
            return Err(format!(
                "{name} and {other} are both shard {}/{}: a pass would count twice",
                part.header.shard, part.header.shards
            ));
        }
    }
    let missing: Vec<String> =
        (1..=f.shards).filter(|k| !owner.contains_key(k)).map(|k| format!("{k}/{}", f.shards)).collect();
    if !missing.is_empty() {
        return Err(format!(
            "incomplete: shard{} {} missing (render {} with the same command and --shard, then merge again)",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", "),
            if missing.len() > 1 { "them" } else { "it" }
        ));
    }
    // Sum in shard order: exact sums make the order irrelevant (module docs).
    let mut ordered: Vec<&Part> = parts.iter().map(|(_, p)| p).collect();
    ordered.sort_by_key(|p| p.header.shard);
    let mut sums = vec![[0.0f64; 3]; (f.width * f.height) as usize];
    let mut passes = 0;
    for part in ordered {
        for (s, p) in sums.iter_mut().zip(&part.sums) {
            for c in 0..3 {
                s[c] += p[c];
            }
        }
        passes += part.header.passes.len() as u32;
    }
    if passes == 0 {
        return Err("the parts hold no passes".into());
    }
    let mut header = f.clone();
    header.passes = parts.iter().flat_map(|(_, p)| p.header.passes.iter().copied()).collect();
    header.passes.sort_unstable();
    Ok(Merged { image: mean_of_sums(f.width, f.height, &sums, passes), passes, header })
}

#[cfg(test)]
mod tests;
