//! The page's options, from its address: `index.html?scene=fog-stage&
//! photons=50000&seed=3&frames=30&panel=0&exposure=1`. Every one is
//! optional; a bad value is an error on the page that names it.

use hikari_core::scene::builtin;

/// Most photon paths a set may have (as `hikari view --photons`).
pub const MAX_PHOTONS: u64 = 100_000_000;

/// Photon paths per set unless `photons=` says otherwise: fewer than the
/// native viewer's 200,000, since a phone or a software adapter traces them.
pub const DEFAULT_PHOTONS: u64 = 100_000;

#[derive(Clone, Debug, PartialEq)]
pub struct PageOptions {
    /// A built-in scene's name.
    pub scene: String,
    pub photons: u64,
    /// The first photon set's seed (set k uses seed + k, as `hikari view`).
    pub seed: u64,
    /// Stop converging after this many frames in the mean, each drawing the
    /// photon set of its own pass (tests and benchmarks compare the image
    /// with `hikari render --passes N`).
    pub frames: Option<u32>,
    pub panel: bool,
    pub exposure: f32,
    /// Where photon sets are traced (`trace=`).
    pub trace: TraceChoice,
}

/// Where the page traces photons, as `hikari view --trace`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TraceChoice {
    /// The compute shader on a hardware adapter, the page's thread on a
    /// software one (SwiftShader), where the "GPU" is the CPU emulating one.
    #[default]
    Auto,
    Gpu,
    Cpu,
}

impl Default for PageOptions {
    fn default() -> Self {
        PageOptions {
            scene: builtin::DEFAULT.to_string(),
            photons: DEFAULT_PHOTONS,
            seed: 0,
            frames: None,
            panel: true,
            exposure: 0.0,
            trace: TraceChoice::Auto,
        }
    }
}

impl PageOptions {
    /// Parses a query string (`location.search`, with or without its `?`).
    pub fn parse(query: &str) -> Result<PageOptions, String> {
        let mut options = PageOptions::default();
        for pair in query.trim_start_matches('?').split('&').filter(|p| !p.is_empty()) {
            let (key, raw) = pair.split_once('=').unwrap_or((pair, ""));
            let value = decode(raw);
            let bad = |what: &str| format!("page address: {key}={value}: {what}");
            match key {
                "scene" => {
                    if builtin::source(&value).is_none() {
                        return Err(bad(&format!("not a built-in scene ({})", builtin::NAMES.join(", "))));
                    }
                    options.scene = value.clone();
                }
                "photons" => {
                    options.photons = value
                        .parse()
                        .ok()
                        .filter(|n| (1..=MAX_PHOTONS).contains(n))
                        .ok_or_else(|| bad("must be a whole number from 1 to 100000000"))?;
                }
                "seed" => options.seed = value.parse().map_err(|_| bad("must be a whole number"))?,
                "frames" => {
                    options.frames = Some(
                        value.parse().ok().filter(|&n| n >= 1).ok_or_else(|| bad("must be a whole number above 0"))?,
                    )
                }
                "panel" => {
                    options.panel = match value.as_str() {
                        "1" | "true" | "on" | "" => true,
                        "0" | "false" | "off" => false,
                        _ => return Err(bad("must be 0 or 1")),
                    }
                }
                "exposure" => {
                    options.exposure = value
                        .parse::<f32>()
                        .ok()
                        .filter(|e| e.abs() <= 64.0)
                        .ok_or_else(|| bad("must be a number of stops from -64 to 64"))?
                }
                "trace" => {
                    options.trace = match value.as_str() {
                        "auto" => TraceChoice::Auto,
                        "gpu" => TraceChoice::Gpu,
                        "cpu" => TraceChoice::Cpu,
                        _ => return Err(bad("must be auto, gpu or cpu")),
                    }
                }
                _ => {
                    return Err(format!(
                        "page address: unknown option `{key}` (scene, photons, seed, frames, panel, exposure, trace)"
                    ));
                }
            }
        }
        Ok(options)
    }
}

/// Percent-decoding of a query value (`+` is a space).
fn decode(raw: &str) -> String {
    let bytes = raw.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'+' => out.push(b' '),
            b'%' if i + 2 < bytes.len() => {
                match u8::from_str_radix(std::str::from_utf8(&bytes[i + 1..i + 3]).unwrap_or("zz"), 16) {
                    Ok(b) => {
                        out.push(b);
                        i += 2;
                    }
                    Err(_) => out.push(b'%'),
                }
            }
            b => out.push(b),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_options_open_the_default_scene() {
        assert_eq!(PageOptions::parse("").unwrap(), PageOptions::default());
        assert_eq!(PageOptions::parse("?").unwrap().scene, "cornell-box");
    }

    #[test]
    fn every_option_is_read() {
        let o = PageOptions::parse("?scene=fog-stage&photons=3000&seed=7&frames=30&panel=0&exposure=-1.5&trace=cpu")
            .unwrap();
        assert_eq!(
            o,
            PageOptions {
                scene: "fog-stage".into(),
                photons: 3000,
                seed: 7,
                frames: Some(30),
                panel: false,
                exposure: -1.5,
                trace: TraceChoice::Cpu,
            }
        );
    }

    #[test]
    fn bad_values_are_named() {
        for (query, expected) in [
            ("scene=teapot", "scene=teapot: not a built-in scene (cornell-box"),
            ("photons=0", "photons=0: must be a whole number from 1"),
            ("photons=many", "photons=many: must be"),
            ("frames=0", "frames=0: must be a whole number above 0"),
            ("panel=maybe", "panel=maybe: must be 0 or 1"),
            ("exposure=99", "exposure=99: must be a number of stops"),
            ("trace=fpga", "trace=fpga: must be auto, gpu or cpu"),
            ("colour=red", "unknown option `colour`"),
        ] {
            let error = PageOptions::parse(query).unwrap_err();
            assert!(error.contains(expected), "{query}: {error}");
        }
    }

    #[test]
    fn values_are_percent_decoded() {
        assert_eq!(decode("fog%2Dstage"), "fog-stage");
        assert_eq!(decode("a+b"), "a b");
        assert_eq!(decode("100%"), "100%");
        assert_eq!(decode("%zz"), "%zz");
    }
}
