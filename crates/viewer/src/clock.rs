//! The viewer's animation clock: real time while playing in a window, or a
//! fixed step per frame in unattended runs (so a run with `--frames` draws
//! the same moments on any machine).

use web_time::Instant;

pub struct AnimationClock {
    time: f32,
    /// Seconds per frame in unattended runs; `None`: the wall clock.
    step: Option<f32>,
    pub playing: bool,
    last: Option<Instant>,
    ticks: u64,
    start: f32,
}

impl AnimationClock {
    pub fn new(start: f32, step: Option<f32>) -> Self {
        AnimationClock { time: start, step, playing: true, last: None, ticks: 0, start }
    }

    /// Advances to the frame drawn at `now` and returns its time: the first
    /// frame is at the start time; later ones a step (or the wall time
    /// since the last frame, while playing) further.
    pub fn tick(&mut self, now: Instant) -> f32 {
        match self.step {
            // Multiplied, not summed, so that frame k is at exactly start + k·step.
            Some(step) => self.time = self.start + self.ticks as f32 * step,
            None => {
                if let (true, Some(last)) = (self.playing, self.last) {
                    // A long stall (a window being dragged) is not a jump in the animation.
                    self.time += (now - last).as_secs_f32().min(0.25);
                }
            }
        }
        self.last = Some(now);
        self.ticks += 1;
        self.time
    }

    pub fn time(&self) -> f32 {
        self.time
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn unattended_frames_are_a_step_apart_from_the_start() {
        let mut clock = AnimationClock::new(1.0, Some(0.1));
        let t0 = Instant::now();
        let times: Vec<f32> = (0..4).map(|k| clock.tick(t0 + Duration::from_secs(k))).collect();
        assert_eq!(times, vec![1.0, 1.1, 1.2, 1.0 + 3.0 * 0.1]);
    }

    #[test]
    fn the_wall_clock_runs_only_while_playing() {
        let mut clock = AnimationClock::new(0.0, None);
        let t0 = Instant::now();
        assert_eq!(clock.tick(t0), 0.0);
        assert!((clock.tick(t0 + Duration::from_millis(100)) - 0.1).abs() < 1e-6);
        clock.playing = false;
        assert!((clock.tick(t0 + Duration::from_millis(200)) - 0.1).abs() < 1e-6);
        clock.playing = true;
        // A stall counts as at most a quarter second.
        assert!((clock.tick(t0 + Duration::from_secs(5)) - 0.35).abs() < 1e-6);
    }
}
