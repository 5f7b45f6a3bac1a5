//! The edge rule the scan and the set-up share: exact i64 edge functions
//! and the tie rule that gives a texel center lying exactly on a shared
//! edge to exactly one of its two triangles.

/// Tie rule for a texel center exactly on an edge (dx, dy): of an edge and its
/// reverse exactly one owns the center, so shared edges are neither cracked
/// nor hit twice.
#[inline]
pub(super) fn owns_ties(dx: i64, dy: i64) -> bool {
    dy < 0 || (dy == 0 && dx > 0)
}

/// Whether the texel center (cx, cy) (subpixel units) is inside the
/// triangle (x, y) by `raster_tri`'s rule: its edge functions, ties
/// included, at one center.
#[inline]
pub(super) fn covers(x: &[i64; 3], y: &[i64; 3], cx: i64, cy: i64) -> bool {
    (0..3).all(|k| {
        let (s, e) = ((k + 1) % 3, (k + 2) % 3);
        let (dx, dy) = (x[e] - x[s], y[e] - y[s]);
        dx * (cy - y[s]) - dy * (cx - x[s]) + owns_ties(dx, dy) as i64 > 0
    })
}
