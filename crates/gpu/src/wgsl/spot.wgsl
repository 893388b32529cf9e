// The spot light's angular falloff.

// Mirrors hikari_core::light::spot_falloff (Mitsuba's convention).
fn spot_falloff(theta: f32, cutoff: f32, falloff_start: f32) -> f32 {
    if (theta >= cutoff) {
        return 0.0;
    }
    if (theta <= falloff_start) {
        return 1.0;
    }
    return (cutoff - theta) / (cutoff - falloff_start);
}
