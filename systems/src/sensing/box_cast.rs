//! The ray test of a box-shaped obstacle in its own frame: parry's
//! (`Cuboid::cast_local_ray`, i.e. `Aabb::cast_local_ray` of `-half..=half`, solid), with the
//! same operations in the same order, without branches, for four rays at once
//! ([`LocalBox::cast4`], one ray per SIMD lane: `super::packet`).
//!
//! Why not call parry's: most of a sweep's ray tests are against boxes (walls, pillars, the
//! ground), and parry's test is an out-of-line call whose slab loop returns early and swaps
//! the slab's ends on data-dependent branches, mispredicted at random over a camera's rays.
//! Here every axis is computed and the answer decided at the end, which gives the same
//! result: the entry parameter only grows and the exit parameter only shrinks from axis to
//! axis, so an interval found empty at one axis stays empty, and an axis the ray does not
//! move along either rejects the ray outright or leaves the interval as it was. Each
//! parameter is the same expression, rounded the same way, as parry's: the hit distances
//! are the same to the bit. The tests below show it on random rays for the one-ray form
//! ([`LocalBox::cast`], the three axes in one register) against parry, and for the
//! four-ray form against the one-ray form; `sweep`'s, against the world's hierarchy.

use super::packet::{Directions, Hits};
use glam::{BVec4A, Vec3A, Vec4};
use parry3d::shape::Cuboid;

/// A box obstacle's shape in its own frame: `lo..=hi` with `lo = -half`, `hi = half`
/// (parry's `Cuboid`, whose ray test builds the same bounds).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalBox {
    lo: Vec3A,
    hi: Vec3A,
}

impl LocalBox {
    pub fn of(cuboid: &Cuboid) -> Self {
        let half = Vec3A::from(cuboid.half_extents);
        Self {
            lo: -half,
            hi: half,
        }
    }

    /// Where the ray `origin + t dir` (in the box's frame) first meets the solid box within
    /// `t <= max_toi` (0 when the origin is inside), or `None`: parry's
    /// `Cuboid::cast_local_ray(ray, max_toi, true)`. The sweeps cast four rays at a time
    /// ([`Self::cast4`]); this one-ray form is the reference the tests hold both to.
    #[cfg(test)]
    pub fn cast(&self, origin: Vec3A, dir: Vec3A, max_toi: f32) -> Option<f32> {
        let Self { lo, hi } = *self;
        // An axis the ray does not move along: outside its slab, never in the box.
        let still = dir.cmpeq(Vec3A::ZERO);
        let rejected = (still & (origin.cmplt(lo) | origin.cmpgt(hi))).any();
        // The three axes' slab parameters at once (lane by lane, parry's operations).
        let denom = Vec3A::ONE / dir;
        let (a, b) = ((lo - origin) * denom, (hi - origin) * denom);
        let swap = a.cmpgt(b);
        let (near, far) = (Vec3A::select(swap, b, a), Vec3A::select(swap, a, b));
        // parry's `enter.max(near)`, `exit.min(far)` axis by axis, as strict comparisons
        // (the same value; a NaN parameter changes neither).
        let mut enter = 0.0_f32;
        let mut exit = max_toi;
        for axis in 0..3 {
            let moves = !still.test(axis);
            enter = if moves && near[axis] > enter {
                near[axis]
            } else {
                enter
            };
            exit = if moves && far[axis] < exit {
                far[axis]
            } else {
                exit
            };
        }
        (!rejected & (enter <= exit)).then_some(enter)
    }

    /// [`Self::cast`] for four rays from one origin (in the box's frame), each with its own
    /// `max_toi`: lane by lane the same operations on the same values, hence the same answers
    /// to the bit (`super::packet`).
    #[inline(always)]
    pub fn cast4(&self, origin: Vec3A, dir: &Directions, max_toi: Vec4) -> Hits {
        let mut rejected = BVec4A::FALSE;
        let mut enter = Vec4::ZERO;
        let mut exit = max_toi;
        for (axis, d) in [dir.x, dir.y, dir.z].into_iter().enumerate() {
            let (o, lo, hi) = (origin[axis], self.lo[axis], self.hi[axis]);
            let still = d.cmpeq(Vec4::ZERO);
            if o < lo || o > hi {
                rejected |= still;
            }
            let denom = Vec4::ONE / d;
            let (a, b) = (Vec4::splat(lo - o) * denom, Vec4::splat(hi - o) * denom);
            let swap = a.cmpgt(b);
            let (near, far) = (Vec4::select(swap, b, a), Vec4::select(swap, a, b));
            let moves = !still;
            enter = Vec4::select(moves & near.cmpgt(enter), near, enter);
            exit = Vec4::select(moves & far.cmplt(exit), far, exit);
        }
        Hits {
            hit: !rejected & enter.cmple(exit),
            toi: enter,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use parry3d::query::{Ray, RayCast};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn cast_local_box(half: Vec3, origin: Vec3, dir: Vec3, max_toi: f32) -> Option<f32> {
        LocalBox::of(&Cuboid::new(half)).cast(origin.into(), dir.into(), max_toi)
    }

    /// parry's own answer.
    fn parry(half: Vec3, origin: Vec3, dir: Vec3, max_toi: f32) -> Option<f32> {
        Cuboid::new(half).cast_local_ray(&Ray::new(origin, dir), max_toi, true)
    }

    #[test]
    fn by_hand() {
        let half = Vec3::new(1.0, 2.0, 0.5);
        // From x = -3 along +x: enters at x = -1, 2 away.
        let hit = cast_local_box(half, Vec3::new(-3.0, 0.0, 0.0), Vec3::X, 10.0);
        assert_eq!(hit, Some(2.0));
        // The same ray with a range short of the box, and pointing away.
        assert_eq!(
            cast_local_box(half, Vec3::new(-3.0, 0.0, 0.0), Vec3::X, 1.5),
            None
        );
        assert_eq!(
            cast_local_box(half, Vec3::new(-3.0, 0.0, 0.0), -Vec3::X, 10.0),
            None
        );
        // Along +x above the box (z = 0.6 > 0.5, an axis it does not move along): missed.
        assert_eq!(
            cast_local_box(half, Vec3::new(-3.0, 0.0, 0.6), Vec3::X, 10.0),
            None
        );
        // From inside: 0.
        assert_eq!(
            cast_local_box(half, Vec3::new(0.5, 0.0, 0.0), Vec3::Y, 10.0),
            Some(0.0)
        );
        // A diagonal that passes the corner: x enters at 2, y leaves at 1 (empty interval).
        assert_eq!(
            cast_local_box(
                half,
                Vec3::new(-3.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                10.0
            ),
            None
        );
    }

    /// A box's half extents.
    fn random_half(rng: &mut ChaCha8Rng) -> Vec3 {
        Vec3::new(
            rng.random_range(0.05..10.0),
            rng.random_range(0.05..10.0),
            rng.random_range(0.05..10.0),
        )
    }

    /// An origin around the box of `half`, on one of its faces' planes now and then.
    fn random_origin(rng: &mut ChaCha8Rng, half: Vec3) -> Vec3 {
        let mut origin = Vec3::new(
            rng.random_range(-15.0..15.0),
            rng.random_range(-15.0..15.0),
            rng.random_range(-15.0..15.0),
        );
        for axis in 0..3 {
            if rng.random_range(0..6) == 0 {
                origin[axis] = half[axis] * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            }
        }
        origin
    }

    /// A direction, with components exactly zero (either sign) now and then: rays along faces
    /// and axes.
    fn random_direction(rng: &mut ChaCha8Rng) -> Vec3 {
        let mut dir = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        for axis in 0..3 {
            match rng.random_range(0..8) {
                0 => dir[axis] = 0.0,
                1 => dir[axis] = -0.0,
                _ => {}
            }
        }
        dir
    }

    #[test]
    fn equals_parry_to_the_bit_on_random_rays() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut hits = 0;
        for case in 0..200_000 {
            let half = random_half(&mut rng);
            let origin = random_origin(&mut rng, half);
            let dir = random_direction(&mut rng);
            let max_toi = rng.random_range(0.0..30.0);
            let expected = parry(half, origin, dir, max_toi);
            let got = cast_local_box(half, origin, dir, max_toi);
            assert_eq!(
                got.map(f32::to_bits),
                expected.map(f32::to_bits),
                "case {case}: half {half} origin {origin} dir {dir} max {max_toi}"
            );
            hits += usize::from(expected.is_some());
        }
        // Both answers occur often.
        assert!((20_000..180_000).contains(&hits), "{hits} hits");
    }

    /// Four rays from one origin at once give each ray's own answer, bit for bit (faces,
    /// zero and negative-zero direction components, origins on faces and inside included).
    #[test]
    fn four_rays_at_once_equal_one_by_one_to_the_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let mut hits = 0;
        for case in 0..50_000 {
            let half = random_half(&mut rng);
            let origin = random_origin(&mut rng, half);
            let directions = [0; 4].map(|_| random_direction(&mut rng));
            let max_toi = Vec4::from_array([0; 4].map(|_| rng.random_range(0.0..30.0)));
            let local_box = LocalBox::of(&Cuboid::new(half));
            let four = local_box.cast4(origin.into(), &Directions::of(&directions), max_toi);
            for (lane, dir) in directions.iter().enumerate() {
                let one = local_box.cast(origin.into(), (*dir).into(), max_toi[lane]);
                let got = four.hit.test(lane).then_some(four.toi[lane]);
                assert_eq!(
                    got.map(f32::to_bits),
                    one.map(f32::to_bits),
                    "case {case}, lane {lane}: half {half} origin {origin} dir {dir}"
                );
                hits += usize::from(one.is_some());
            }
        }
        assert!((20_000..180_000).contains(&hits), "{hits} hits");
    }
}
