//! Shared by the GPU tests: find an adapter, or fail under CI.

use crate::context::GpuContext;

/// The GPU context for a test. Without an adapter the test is skipped, except
/// when `CI=true`: CI installs lavapipe, so a missing adapter there is a failure.
pub fn context_or_skip(test: &str) -> Option<GpuContext> {
    match GpuContext::new() {
        Ok(ctx) => Some(ctx),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => {
            panic!("{test}: CI=true but no GPU adapter: {e} (is mesa-vulkan-drivers installed?)")
        }
        Err(e) => {
            eprintln!("{test}: skipped, {e}");
            None
        }
    }
}
