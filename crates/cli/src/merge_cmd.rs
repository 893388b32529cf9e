//! `hikari merge`: the parts that `render --shard K/M` wrote, added up into
//! the image one run of all the passes makes (`progressive::shard`).

use crate::render_cmd::UsageError;
use anyhow::Result;
use clap::Args;
use hikari_core::output::write_image;
use hikari_core::progressive::shard::{Part, merge};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The parts (`render --shard K/M -o part-K.exr`), in any order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// The merged image: .exr (linear) or .png (tone-mapped).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Exposure in stops applied before PNG tone mapping (-64 to 64).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    let ext = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        return Err(UsageError(format!("{}: unsupported image type (use .png or .exr)", args.output.display())).into());
    }
    if !(args.exposure.abs() <= 64.0) {
        return Err(UsageError(format!("--exposure {}: must be between -64 and 64 stops", args.exposure)).into());
    }
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        let name = path.display().to_string();
        let part = Part::read(path).map_err(|e| UsageError(format!("{name}: {e}")))?;
        parts.push((name, part));
    }
    let merged = merge(&parts).map_err(UsageError)?;
    write_image(&args.output, &merged.image, args.exposure)?;
    let h = &merged.header;
    eprintln!(
        "wrote {} ({}x{}): {} passes of {} from {} parts ({}, {})",
        args.output.display(),
        h.width,
        h.height,
        merged.passes,
        h.total_passes.map_or("an open-ended render".to_string(), |n| format!("{n}")),
        parts.len(),
        h.renderer,
        h.scene
    );
    Ok(())
}
