//! Primitive intersection routines.

use super::Ray;
use glam::Vec3;

/// A triangle with its vertices and (optional) per-vertex smooth normals.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub v: [Vec3; 3],
    pub normals: Option<TriangleNormals>,
}

#[derive(Clone, Copy, Debug)]
pub struct TriangleNormals(pub [Vec3; 3]);

impl Triangle {
    /// Möller–Trumbore; returns (t, b1, b2) with t in (t_min, ray.t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f32) -> Option<(f32, f32, f32)> {
        let e1 = self.v[1] - self.v[0];
        let e2 = self.v[2] - self.v[0];
        let p = ray.dir.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return None;
        }
        let inv = 1.0 / det;
        let s = ray.origin - self.v[0];
        let b1 = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&b1) {
            return None;
        }
        let q = s.cross(e1);
        let b2 = ray.dir.dot(q) * inv;
        if b2 < 0.0 || b1 + b2 > 1.0 {
            return None;
        }
        let t = e2.dot(q) * inv;
        (t > t_min && t < ray.t_max).then_some((t, b1, b2))
    }

    /// Unnormalised geometric normal, following the vertex winding.
    pub fn geometric_normal(&self) -> Vec3 {
        (self.v[1] - self.v[0]).cross(self.v[2] - self.v[0])
    }

    pub fn area(&self) -> f32 {
        0.5 * self.geometric_normal().length()
    }

    /// Shading normal at barycentrics (b1, b2); the geometric one without smooth normals.
    pub fn shading_normal(&self, b1: f32, b2: f32) -> Vec3 {
        match self.normals {
            Some(TriangleNormals(n)) => {
                let s = n[0] * (1.0 - b1 - b2) + n[1] * b1 + n[2] * b2;
                let len = s.length();
                if len > 0.0 && len.is_finite() { s / len } else { self.geometric_normal().normalize() }
            }
            None => self.geometric_normal().normalize(),
        }
    }
}

/// An analytic sphere; its normal points outwards.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

impl Sphere {
    /// Nearest root in (t_min, ray.t_max); numerically stable form.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f32) -> Option<f32> {
        let oc = ray.origin - self.center;
        let a = ray.dir.length_squared();
        let half_b = oc.dot(ray.dir);
        // Distance² from the centre to the ray's line, without cancellation.
        let closest = oc - ray.dir * (half_b / a);
        let disc = self.radius * self.radius - closest.length_squared();
        if disc < 0.0 {
            return None;
        }
        let root = (a * disc).sqrt();
        let q = -half_b - root.copysign(half_b);
        let (mut t0, mut t1) =
            (q / a, if q != 0.0 { (oc.length_squared() - self.radius * self.radius) / q } else { q / a });
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        if t0 > t_min && t0 < ray.t_max {
            Some(t0)
        } else if t1 > t_min && t1 < ray.t_max {
            Some(t1)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_hits_from_outside_and_inside() {
        let s = Sphere { center: Vec3::ZERO, radius: 1.0 };
        let r = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        assert!((s.intersect(&r, 1e-4).unwrap() - 4.0).abs() < 1e-5);
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert!((s.intersect(&inside, 1e-4).unwrap() - 1.0).abs() < 1e-5);
        let miss = Ray::new(Vec3::new(0.0, 2.0, 5.0), -Vec3::Z);
        assert!(s.intersect(&miss, 1e-4).is_none());
    }

    #[test]
    fn triangle_hit_and_barycentrics() {
        let tri = Triangle { v: [Vec3::ZERO, Vec3::X, Vec3::Y], normals: None };
        let r = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        let (t, b1, b2) = tri.intersect(&r, 1e-4).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.25).abs() < 1e-6 && (b2 - 0.25).abs() < 1e-6);
        let miss = Ray::new(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z);
        assert!(tri.intersect(&miss, 1e-4).is_none());
    }
}
