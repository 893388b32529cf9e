//! `hikari render --passes N` / `--time SECONDS`: progressive rendering
//! (docs/progressive.md) on the terminal. The engine's session renders and
//! stops the passes; this shows them in a bar, stops them on Ctrl-C (the
//! image so far is then written), writes checkpoints, and compares with a
//! reference image.

use anyhow::{Result, anyhow};
use hikari_core::output::write_image;
use hikari_core::progressive::compare;
use hikari_core::progressive::shard::Shard;
use hikari_core::render::Image;
use hikari_engine::{Outcome, Session};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// What the terminal shows and writes while the passes run.
pub struct Reporting {
    /// Which of the passes run (for the closing line).
    pub shard: Option<Shard>,
    /// Write the image so far (and compare it) this often.
    pub checkpoint: Option<Duration>,
    /// A reference image to compare with, and its path.
    pub reference: Option<(PathBuf, Image)>,
    pub output: PathBuf,
    pub exposure: f32,
    pub quiet: bool,
}

/// Set by Ctrl-C: the loop ends after the pass under way. A second Ctrl-C
/// ends the process at once (no file is half written: images are written
/// to a temporary name and renamed).
fn interrupted() -> Arc<AtomicBool> {
    static FLAG: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        let seen = flag.clone();
        let installed = ctrlc::set_handler(move || {
            if seen.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
            eprintln!("\nCtrl-C: finishing this pass, then writing the image (Ctrl-C again to quit now)");
        });
        if let Err(e) = installed {
            eprintln!("note: Ctrl-C will not stop the render gracefully ({e})");
        }
        flag
    })
    .clone()
}

/// Prints the error of `image` against the reference, if any.
fn report(reporting: &Reporting, image: &Image, pass: u32, seconds: f64) -> Result<()> {
    let Some((path, reference)) = &reporting.reference else { return Ok(()) };
    let e = compare(image, reference).map_err(|e| anyhow!("--reference {}: {e}", path.display()))?;
    println!("pass {pass}, {seconds:.2} s: {e}");
    Ok(())
}

/// Runs the session's passes with a bar, checkpoints and the reference's
/// error; Ctrl-C stops them after the pass under way.
pub fn run(session: Session, reporting: &Reporting) -> Result<Outcome> {
    let session = session.interrupt_on(interrupted());
    let planned = session.planned_passes();
    let bar = if reporting.quiet {
        ProgressBar::with_draw_target(Some(planned as u64), ProgressDrawTarget::hidden())
    } else if planned == u32::MAX {
        ProgressBar::new_spinner()
    } else {
        ProgressBar::new(planned as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{msg:>40} [{bar:30}] {pos}/{len} passes {elapsed_precise} eta {eta}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let mut last_checkpoint = Instant::now();
    let outcome = session.run(|pass, session| {
        bar.inc(1);
        let mut message = pass.noise.map_or(String::new(), |e| format!("noise ≈ {:.2}%", 100.0 * e));
        if let Some(r) = pass.next_radius {
            message = format!("{message}{}next radius {r:.5}", if message.is_empty() { "" } else { ", " });
        }
        bar.set_message(message);
        if pass.last.is_none() && reporting.checkpoint.is_some_and(|c| last_checkpoint.elapsed() >= c) {
            last_checkpoint = Instant::now();
            let image = session.image()?;
            write_image(&reporting.output, &image, reporting.exposure)?;
            bar.suspend(|| report(reporting, &image, pass.count, pass.seconds))?;
        }
        Ok(())
    })?;
    bar.finish_and_clear();
    let count = outcome.passes.len() as u32;
    let noise = outcome.noise.map_or(String::new(), |e| format!("; estimated noise {:.2}%", 100.0 * e));
    let shard = reporting
        .shard
        .map_or(String::new(), |s| format!(" of shard {}/{} ({})", s.index, s.count, list(&outcome.passes)));
    eprintln!(
        "{count} passes{shard} in {:.2} s (stopped by {}){noise}",
        outcome.seconds,
        outcome.stopped_by.describe()
    );
    report(reporting, &outcome.image, count, outcome.seconds)?;
    Ok(outcome)
}

/// "1, 4, 7" (at most a few, then "…").
fn list(passes: &[u32]) -> String {
    let shown: Vec<String> = passes.iter().take(6).map(u32::to_string).collect();
    format!("passes {}{}", shown.join(", "), if passes.len() > 6 { ", …" } else { "" })
}

/// Reads a reference image: linear float RGB from an EXR file.
pub fn read_reference(path: &Path) -> Result<Image> {
    hikari_core::output::read_exr(path).map_err(|e| anyhow!("--reference {}: {e}", path.display()))
}
