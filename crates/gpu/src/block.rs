//! Waiting for the GPU. Natively a caller may block until a future is
//! done; in a browser nothing may (the page's one thread is what resolves
//! the promises), so there the blocking entry points return an error that
//! names the mistake and the web viewer calls their `_async` twins.

use crate::context::GpuError;

/// Runs `future` to completion, blocking the thread (not in a browser).
pub fn wait_for<T>(future: impl Future<Output = Result<T, GpuError>>) -> Result<T, GpuError> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        pollster::block_on(future)
    }
    #[cfg(target_arch = "wasm32")]
    {
        drop(future);
        Err(GpuError::Failed(
            "a blocking GPU wait was called in a browser, where only the asynchronous calls work".into(),
        ))
    }
}
