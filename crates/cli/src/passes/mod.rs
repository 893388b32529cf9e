//! `hikari render --passes N` / `--time SECONDS`: progressive rendering
//! (docs/progressive.md). Each renderer renders pass after pass into its
//! running mean; this loop stops at the pass count, the time limit or
//! Ctrl-C (the image so far is then written), writes checkpoints, and
//! compares with a reference image.

pub mod renderers;

use anyhow::{Result, anyhow};
use hikari_core::output::write_image;
use hikari_core::progressive::compare;
use hikari_core::progressive::shard::Shard;
use hikari_core::render::Image;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// One renderer, pass by pass.
pub trait PassRenderer {
    /// Renders pass `pass` (from 1) and adds it to the mean.
    fn render_pass(&mut self, pass: u32) -> Result<()>;
    /// The mean of the passes so far.
    fn mean(&mut self) -> Result<Image>;
    /// The global map's radius in pass `pass`, for the progress bar (None: no radius).
    fn radius(&self, pass: u32) -> Option<f32>;
    /// The mean's relative error as its passes estimate it
    /// (`ImageMean::noise_estimate`); None before the second pass.
    fn noise(&mut self) -> Option<f64> {
        None
    }
    /// The per-pixel sums of the passes so far (row-major), what a shard
    /// of the render keeps for the merge.
    fn sums(&mut self) -> Result<Vec<[f64; 3]>>;
}

/// When to stop and what to report.
pub struct PassPlan {
    /// At most this many passes: passes 1..=passes, or a shard's share of them.
    pub passes: u32,
    /// Which of the passes to render (`--shard K/M`: K, K + M, …; None: all).
    pub shard: Option<Shard>,
    /// Stop after the first pass that ends past this.
    pub time: Option<Duration>,
    /// Write the image so far (and compare it) this often.
    pub checkpoint: Option<Duration>,
    /// A reference image to compare with, and its path.
    pub reference: Option<(PathBuf, Image)>,
    /// Stop once the estimated noise (relative to the mean) is this low,
    /// from the fourth pass on.
    pub target_error: Option<f64>,
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

/// Prints the error of `image` against the plan's reference, if any.
fn report(plan: &PassPlan, image: &Image, pass: u32, seconds: f64) -> Result<()> {
    let Some((path, reference)) = &plan.reference else { return Ok(()) };
    let e = compare(image, reference).map_err(|e| anyhow!("--reference {}: {e}", path.display()))?;
    println!("pass {pass}, {seconds:.2} s: {e}");
    Ok(())
}

/// What a run of passes made.
pub struct Outcome {
    pub image: Image,
    /// The passes rendered, in order.
    pub passes: Vec<u32>,
    /// Whether it stopped before its last pass (time, target error, Ctrl-C).
    pub stopped_early: bool,
}

/// Runs the plan's passes (its shard's share of 1..=passes) in order.
pub fn run(renderer: &mut dyn PassRenderer, plan: &PassPlan) -> Result<Outcome> {
    let stop = interrupted();
    let bar = if plan.quiet {
        ProgressBar::with_draw_target(Some(plan.passes as u64), ProgressDrawTarget::hidden())
    } else if plan.passes == u32::MAX {
        ProgressBar::new_spinner()
    } else {
        ProgressBar::new(plan.shard.unwrap_or(Shard::WHOLE).len(plan.passes) as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{msg:>40} [{bar:30}] {pos}/{len} passes {elapsed_precise} eta {eta}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let start = Instant::now();
    let mut last_checkpoint = start;
    let mut rendered = Vec::new();
    let mut upcoming = plan.shard.unwrap_or(Shard::WHOLE).passes(plan.passes).peekable();
    let why = loop {
        let Some(pass) = upcoming.next() else { break "the pass count" };
        renderer.render_pass(pass)?;
        rendered.push(pass);
        bar.inc(1);
        let noise = renderer.noise();
        let mut message = noise.map_or(String::new(), |e| format!("noise ≈ {:.2}%", 100.0 * e));
        if let Some(r) = upcoming.peek().and_then(|&next| renderer.radius(next)) {
            message = format!("{message}{}next radius {r:.5}", if message.is_empty() { "" } else { ", " });
        }
        bar.set_message(message);
        let elapsed = start.elapsed();
        if upcoming.peek().is_none() {
            break "the pass count";
        }
        if rendered.len() >= 4 && plan.target_error.zip(noise).is_some_and(|(target, e)| e <= target) {
            break "the target error";
        }
        if plan.time.is_some_and(|t| elapsed >= t) {
            break "the time limit";
        }
        if stop.load(Ordering::SeqCst) {
            break "Ctrl-C";
        }
        if plan.checkpoint.is_some_and(|c| last_checkpoint.elapsed() >= c) {
            last_checkpoint = Instant::now();
            let image = renderer.mean()?;
            write_image(&plan.output, &image, plan.exposure)?;
            bar.suspend(|| report(plan, &image, rendered.len() as u32, elapsed.as_secs_f64()))?;
        }
    };
    let count = rendered.len() as u32;
    bar.finish_and_clear();
    let image = renderer.mean()?;
    let seconds = start.elapsed().as_secs_f64();
    let noise = renderer.noise().map_or(String::new(), |e| format!("; estimated noise {:.2}%", 100.0 * e));
    let shard =
        plan.shard.map_or(String::new(), |s| format!(" of shard {}/{} ({})", s.index, s.count, list(&rendered)));
    eprintln!("{count} passes{shard} in {seconds:.2} s (stopped by {why}){noise}");
    report(plan, &image, count, seconds)?;
    let stopped_early = upcoming.peek().is_some();
    Ok(Outcome { image, passes: rendered, stopped_early })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Passes whose images are the pass number: the mean of n passes is (n + 1) / 2.
    struct Counting(u32);

    impl PassRenderer for Counting {
        fn render_pass(&mut self, pass: u32) -> Result<()> {
            assert_eq!(pass, self.0 + 1, "passes come in order");
            self.0 = pass;
            Ok(())
        }
        fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
            unreachable!()
        }
        fn mean(&mut self) -> Result<Image> {
            let mut image = Image::new(1, 1);
            image.pixels[0] = glam::Vec3::splat((self.0 + 1) as f32 / 2.0);
            Ok(image)
        }
        fn radius(&self, _: u32) -> Option<f32> {
            None
        }
    }

    fn plan(passes: u32, time: Option<Duration>) -> PassPlan {
        PassPlan {
            passes,
            shard: None,
            time,
            checkpoint: None,
            reference: None,
            target_error: None,
            output: std::env::temp_dir().join("hikari-passes-test.exr"),
            exposure: 0.0,
            quiet: true,
        }
    }

    #[test]
    fn stops_at_the_pass_count_or_the_time_limit() {
        let done = run(&mut Counting(0), &plan(5, None)).unwrap();
        assert_eq!((done.passes.len(), done.image.pixels[0].x, done.stopped_early), (5, 3.0, false));
        let done = run(&mut Counting(0), &plan(u32::MAX, Some(Duration::ZERO))).unwrap();
        assert_eq!((done.passes.len(), done.stopped_early), (1, true), "a time limit still renders one pass");
    }

    /// Records the passes it is asked for.
    struct Recording(Vec<u32>);

    impl PassRenderer for Recording {
        fn render_pass(&mut self, pass: u32) -> Result<()> {
            self.0.push(pass);
            Ok(())
        }
        fn mean(&mut self) -> Result<Image> {
            Ok(Image::new(1, 1))
        }
        fn radius(&self, _: u32) -> Option<f32> {
            None
        }
        fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
            Ok(vec![[0.0; 3]])
        }
    }

    #[test]
    fn a_shard_renders_its_share_of_the_passes() {
        let shard = |k, m| PassPlan { shard: Some(Shard { index: k, count: m }), ..plan(7, None) };
        for (k, m, expected) in [(1, 3, vec![1, 4, 7]), (3, 3, vec![3, 6]), (7, 7, vec![7]), (2, 2, vec![2, 4, 6])] {
            let mut recording = Recording(Vec::new());
            let done = run(&mut recording, &shard(k, m)).unwrap();
            assert_eq!((&recording.0, &done.passes, done.stopped_early), (&expected, &expected, false));
        }
        // More shards than passes: shard 9 of 9 has none of 7.
        let mut recording = Recording(Vec::new());
        assert!(run(&mut recording, &shard(9, 9)).unwrap().passes.is_empty());
    }

    /// Passes whose noise estimate is 1/n: a target of 0.1 stops at pass
    /// 10; a target met at once still renders 4 passes.
    struct Quieting(Counting);

    impl PassRenderer for Quieting {
        fn render_pass(&mut self, pass: u32) -> Result<()> {
            self.0.render_pass(pass)
        }
        fn mean(&mut self) -> Result<Image> {
            self.0.mean()
        }
        fn radius(&self, _: u32) -> Option<f32> {
            None
        }
        fn noise(&mut self) -> Option<f64> {
            Some(1.0 / self.0.0 as f64)
        }
        fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
            self.0.sums()
        }
    }

    #[test]
    fn stops_at_the_target_error() {
        let target = |t| PassPlan { target_error: Some(t), ..plan(u32::MAX, None) };
        let passes = |done: Outcome| done.passes.len();
        assert_eq!(passes(run(&mut Quieting(Counting(0)), &target(0.1)).unwrap()), 10);
        assert_eq!(passes(run(&mut Quieting(Counting(0)), &target(0.9)).unwrap()), 4);
        assert_eq!(passes(run(&mut Counting(0), &PassPlan { target_error: Some(0.5), ..plan(7, None) }).unwrap()), 7);
    }
}
