//! Per-axis arithmetic on the walk's `[_; 3]` arrays (steps, boundary times, intervals),
//! always inlined.
//!
//! Why not `array::map`: it goes through `core::array::try_map`, which LLVM inlines or not
//! depending on how the crate's code falls into codegen units, so that a change anywhere else
//! in the crate could leave a call to it in the walk. One such call, in a walk's start (the
//! bit steps of its brick runs), appeared when the traversability refresh changed
//! (2026-12-06): the registers the walk keeps across it spilled to the stack, and the map
//! update ran 13 % slower with its own code unchanged. Here the three lanes are written out.

/// `[f(a[0]), f(a[1]), f(a[2])]`.
#[inline(always)]
pub(super) fn per_axis<T: Copy, U>(a: [T; 3], f: impl Fn(T) -> U) -> [U; 3] {
    [f(a[0]), f(a[1]), f(a[2])]
}

/// `[f(0), f(1), f(2)]`: a lane computed from its axis index.
#[inline(always)]
pub(super) fn by_axis<U>(f: impl Fn(usize) -> U) -> [U; 3] {
    [f(0), f(1), f(2)]
}

/// All ones if `c`, else zero: a branch-free select (`x & mask(c)`) for the walks' choice of
/// axis, whose outcome no predictor knows.
#[inline(always)]
pub(super) fn mask(c: bool) -> i64 {
    -i64::from(c)
}
