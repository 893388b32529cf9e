//! Progress reporting for long work (photon tracing, rendering). The core
//! reports through this trait; the CLI draws bars, tests stay silent.

pub trait Progress: Sync {
    fn begin(&self, _stage: &str, _total: u64) {}
    fn advance(&self, _amount: u64) {}
    fn end(&self) {}
}

/// Reports nothing.
pub struct Silent;

impl Progress for Silent {}
