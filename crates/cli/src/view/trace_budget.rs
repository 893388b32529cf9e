//! "Trace every frame": the photon count per set that lets the background
//! tracer finish one set per frame, from the measured tracing rate and
//! frame time (both smoothed, so one slow frame does not halve the count).
//!
//! The frame counted is at most 1/60 s. Drawing more photons takes longer
//! too, so sizing sets to a frame that the sets themselves lengthen would
//! grow them without end on an adapter whose splat is slower than tracing
//! (lavapipe: 7.8 M photons per set within 60 frames, measured); capped,
//! the count settles where tracing keeps up with 60 fps or with the frame
//! rate the adapter reaches, whichever is slower to trace for.

/// Fewest and most photons per set the budget chooses.
pub const MIN_PHOTONS: u64 = 1_000;
pub const MAX_PHOTONS: u64 = 10_000_000;

/// The longest frame a set is sized for (60 fps).
pub const LONGEST_FRAME: f64 = 1.0 / 60.0;

#[derive(Debug)]
pub struct TraceBudget {
    /// Photon paths per second, and seconds per frame (moving averages).
    rate: Option<f64>,
    frame: Option<f64>,
    /// The most photons per set the adapter took (lowered when a set was too large).
    pub cap: u64,
}

impl Default for TraceBudget {
    fn default() -> Self {
        TraceBudget { rate: None, frame: None, cap: MAX_PHOTONS }
    }
}

/// Weight of a new measurement in the moving averages.
const SMOOTHING: f64 = 0.25;

fn blend(average: &mut Option<f64>, value: f64) {
    if value.is_finite() && value > 0.0 {
        *average = Some(average.map_or(value, |a| a + SMOOTHING * (value - a)));
    }
}

impl TraceBudget {
    /// A set of `photons` paths took `seconds` to pose and trace.
    pub fn traced(&mut self, photons: u64, seconds: f64) {
        blend(&mut self.rate, photons as f64 / seconds);
    }

    /// A frame took `seconds` (between presents).
    pub fn frame(&mut self, seconds: f64) {
        blend(&mut self.frame, seconds);
    }

    /// Photons per set to trace one set per frame (90% of a frame of at
    /// most `LONGEST_FRAME`, leaving room for the upload); `fallback` until
    /// both are measured.
    pub fn photons(&self, fallback: u64) -> u64 {
        match (self.rate, self.frame) {
            (Some(rate), Some(frame)) => {
                ((0.9 * rate * frame.min(LONGEST_FRAME)) as u64).clamp(MIN_PHOTONS, self.cap.max(MIN_PHOTONS))
            }
            _ => fallback.min(self.cap),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_set_takes_about_one_frame() {
        let mut budget = TraceBudget::default();
        assert_eq!(budget.photons(123), 123);
        budget.traced(100_000, 0.1); // 1 M paths/s
        budget.frame(0.01);
        assert!((8_990..=9_010).contains(&budget.photons(123)));
        // The averages move a quarter of the way toward a new measurement.
        budget.frame(0.014);
        assert!((9_890..=9_910).contains(&budget.photons(123)));
        // Frames slower than 60 fps count as 1/60 s.
        budget.frame(1.0);
        assert!((14_990..=15_010).contains(&budget.photons(123)));
    }

    #[test]
    fn the_count_stays_within_bounds() {
        let mut budget = TraceBudget::default();
        budget.traced(1_000, 10.0);
        budget.frame(0.001);
        assert_eq!(budget.photons(5), MIN_PHOTONS);
        budget.traced(1_000_000_000, 0.001);
        budget.frame(f64::NAN);
        budget.frame(100.0);
        assert_eq!(budget.photons(5), MAX_PHOTONS);
        budget.cap = 50_000;
        assert_eq!(budget.photons(5), 50_000);
    }
}
