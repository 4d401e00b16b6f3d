//! Four rays of one sweep at a time, component by component (x, y and z of the four in one SIMD
//! register each), for the ray tests against box obstacles (`super::box_cast`).
//!
//! Why: a sweep's rays share their origin, and a box's test of one ray is some forty
//! floating-point operations on three lanes of a register (the rotation into the box's frame,
//! then the slabs), the fourth lane idle and the three axes combined by shuffles. Four rays in
//! four lanes do the same operations once for all four. Every lane computes exactly what the
//! one-ray code computes for its ray, the same operations on the same values in the same order
//! (IEEE arithmetic rounds each operation alone, whatever the register), so the answers are the
//! same to the bit: tested below against glam's rotation and in `super::box_cast` against
//! parry's ray test.

use glam::{BVec4A, Quat, Vec3, Vec4};

/// Rays per packet.
pub const LANES: usize = 4;

/// The directions of four rays, by component.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Directions {
    pub x: Vec4,
    pub y: Vec4,
    pub z: Vec4,
}

impl Directions {
    pub fn of(directions: &[Vec3; LANES]) -> Self {
        let [a, b, c, d] = *directions;
        Self {
            x: Vec4::new(a.x, b.x, c.x, d.x),
            y: Vec4::new(a.y, b.y, c.y, d.y),
            z: Vec4::new(a.z, b.z, c.z, d.z),
        }
    }

    /// Direction `lane`.
    pub fn lane(&self, lane: usize) -> Vec3 {
        Vec3::new(self.x[lane], self.y[lane], self.z[lane])
    }

    /// The four directions rotated by `rotation` (unit): glam's `Quat::mul_vec3a` lane by lane,
    /// `v (w^2 - b.b) + b (2 v.b) + (2 w) (b x v)` with `b` the vector part, each term and sum
    /// rounded in its order (the dot products summed x, y, then z; the cross product's
    /// components as differences of two products).
    #[inline(always)]
    pub fn rotated(&self, rotation: Quat) -> Self {
        let (bx, by, bz, w) = (rotation.x, rotation.y, rotation.z, rotation.w);
        let b_dot_b = bx * bx + by * by + bz * bz;
        let scale_v = w * w - b_dot_b;
        let twice_w = w * 2.0;
        let Self { x, y, z } = *self;
        let twice_v_dot_b = (x * bx + y * by + z * bz) * 2.0;
        let cross_x = z * by - y * bz;
        let cross_y = x * bz - z * bx;
        let cross_z = y * bx - x * by;
        Self {
            x: x * scale_v + twice_v_dot_b * bx + cross_x * twice_w,
            y: y * scale_v + twice_v_dot_b * by + cross_y * twice_w,
            z: z * scale_v + twice_v_dot_b * bz + cross_z * twice_w,
        }
    }
}

/// The answers of four ray tests: where each ray hits (valid in the lanes of `hit`).
#[derive(Debug, Clone, Copy)]
pub struct Hits {
    pub hit: BVec4A,
    pub toi: Vec4,
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    // The scenes' yaws are written 1.5708, not pi/2: the quarter turns below are theirs.
    #[allow(clippy::approx_constant)]
    fn rotating_four_at_once_equals_glam_to_the_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let random = |rng: &mut ChaCha8Rng| {
            Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        };
        for case in 0..20_000 {
            let axis = random(&mut rng).normalize_or(Vec3::Z);
            let rotation = match case % 4 {
                // Quarter turns about z, as the boxes of the shipped scenes (yaw +-1.5708).
                0 => Quat::from_rotation_z(1.5708 * f32::from(rng.random_range(-2i8..=2))),
                _ => Quat::from_axis_angle(axis, rng.random_range(-4.0..4.0)),
            };
            let directions = [0; LANES].map(|_| random(&mut rng).normalize_or(Vec3::X));
            let rotated = Directions::of(&directions).rotated(rotation);
            for (lane, direction) in directions.iter().enumerate() {
                let expected = rotation.mul_vec3a(Vec3A::from(*direction));
                let got = rotated.lane(lane);
                assert_eq!(
                    got.to_array().map(f32::to_bits),
                    expected.to_array().map(f32::to_bits),
                    "case {case}, lane {lane}: {rotation} {direction}"
                );
            }
        }
    }
}
