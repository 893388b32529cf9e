// Constants every shader shares.

const PI: f32 = 3.14159265358979323846;
