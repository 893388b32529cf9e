//! Frame times of a viewer session: mean fps and the 1% low (the fps of the
//! slowest 1% of frames), the figures games and benchmarks report.

#[derive(Default, Debug)]
pub struct FrameStats {
    seconds: Vec<f64>,
}

impl FrameStats {
    pub fn push(&mut self, seconds: f64) {
        self.seconds.push(seconds);
    }

    pub fn frames(&self) -> usize {
        self.seconds.len()
    }

    /// Frames per second over all frames.
    pub fn mean_fps(&self) -> f64 {
        let total: f64 = self.seconds.iter().sum();
        if total > 0.0 { self.seconds.len() as f64 / total } else { 0.0 }
    }

    /// Frames per second over the slowest 1% of frames (at least one).
    pub fn one_percent_low_fps(&self) -> f64 {
        let mut slow = self.seconds.clone();
        slow.sort_by(|a, b| b.total_cmp(a));
        let n = slow.len().div_ceil(100).max(1).min(slow.len());
        let total: f64 = slow[..n].iter().sum();
        if total > 0.0 { n as f64 / total } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_one_percent_low() {
        let mut stats = FrameStats::default();
        for _ in 0..198 {
            stats.push(0.01);
        }
        stats.push(0.1);
        stats.push(0.05);
        assert_eq!(stats.frames(), 200);
        assert!((stats.mean_fps() - 200.0 / (1.98 + 0.15)).abs() < 1e-9);
        // The slowest 1% of 200 frames: the 0.1 s and the 0.05 s frames.
        assert!((stats.one_percent_low_fps() - 2.0 / 0.15).abs() < 1e-9);
        assert_eq!(FrameStats::default().mean_fps(), 0.0);
    }
}
