//! A result's error, estimated from exact rays at a random subset of its
//! pixels (texels): the statistics, free of any view or method.
//!
//! The quantity is the headline metric (docs/accuracy.md): the mean
//! |V − V_ref| over the pixels the reference shadows (occlusion above
//! `SHADOW_THRESHOLD`). The pixels are grouped in units (a few neighbours,
//! traced together so that their rays stay coherent), the units split in
//! strata (those in the result's own shadow, and the rest), a simple random
//! sample of units is drawn in each, and each drawn pixel gets V_ref from
//! exact rays. Per unit j, y_j = Σ_i s_i |ΔV_i| and x_j = Σ_i s_i, s_i = 1
//! where the reference shadows pixel i. With N_h units and n_h drawn in
//! stratum h, each drawn unit stands for N_h / n_h of its stratum, and the
//! error is the ratio of two such totals (a cluster sample's ratio),
//!     E = Σ_h (N_h/n_h) Σ_j y_j  /  Σ_h (N_h/n_h) Σ_j x_j.
//! Its variance is the stratified ratio estimator's (Cochran 1977, §6.11):
//! with the residuals d_j = y_j − E x_j,
//!     Var(E) ≈ Σ_h N_h² (1 − n_h/N_h) var_h(d) / n_h  /  X²,
//! X the estimated count of shadowed pixels, and the interval is
//! E ± 1.96 sqrt(Var(E)), clamped to [0, 1]: a normal approximation, too
//! narrow when the error comes from rare pixels (measured in the tests).
//! Drawing more units where the result has a shadow spends the rays where
//! the error lives, and the weights keep the estimate unbiased for the lit
//! rest (a missed shadow shows up there).

/// Occlusion above which a reference pixel is in shadow (as
/// `softshadow.metrics.shadow_mask`).
pub const SHADOW_THRESHOLD: f32 = 1e-3;

/// The estimate of a result's error over the pixels the reference shadows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimate {
    /// The estimated mean |V − V_ref| over the shadowed pixels.
    pub error: f64,
    /// A 95% confidence interval around it, within [0, 1]. (0, 1) when no
    /// drawn pixel is in the reference shadow: nothing is known.
    pub low: f64,
    pub high: f64,
    /// Pixels traced, and how many of them the exact rays found in shadow.
    pub traced: usize,
    pub shadowed: usize,
    /// Light samples per traced pixel.
    pub samples: u32,
    /// Seconds the estimate took (tracing included).
    pub seconds: f64,
}

/// How many pixels an estimate draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Draw {
    /// Batches while the estimate has spent less than a set share of the
    /// call so far (the first batch always): its cost a bounded share of
    /// the call, its pixel count the machine's (`estimate_error=True`).
    Timed,
    /// A set count of pixels, whatever the time: the same inputs draw the
    /// same pixels and give the same estimate, so a plan checked against it
    /// (`Auto` with a target, `crate::auto::refine`) gives the same bits.
    Fixed,
}

impl Draw {
    /// The draw named by the API's `estimate_error` (`True` is "timed").
    pub fn parse(name: &str) -> crate::error::Result<Draw> {
        match name {
            "timed" => Ok(Draw::Timed),
            "fixed" => Ok(Draw::Fixed),
            other => Err(crate::error::Error::invalid(
                "estimate_error",
                format!("must be True, False, \"timed\" or \"fixed\", got {other:?}"),
            )),
        }
    }
}

/// One stratum: its size in units and, per drawn unit, its pixels' pairs
/// (the result's visibility, the exact one).
#[derive(Debug, Clone, Default)]
pub struct Stratum {
    pub population: usize,
    pub drawn: Vec<Vec<(f32, f32)>>,
}

/// A unit's (y, x): the sum of |ΔV| over its pixels in the reference
/// shadow, and their count.
fn unit_sums(pixels: &[(f32, f32)]) -> (f64, f64) {
    pixels
        .iter()
        .filter(|p| 1.0 - p.1 > SHADOW_THRESHOLD)
        .fold((0.0, 0.0), |(y, x), &(v, r)| {
            (y + (v as f64 - r as f64).abs(), x + 1.0)
        })
}

/// (error, low, high, shadowed pixels drawn) from the strata (module docs).
pub fn ratio_estimate(strata: &[Stratum]) -> (f64, f64, f64, usize) {
    let sums: Vec<Vec<(f64, f64)>> = strata
        .iter()
        .map(|s| s.drawn.iter().map(|u| unit_sums(u)).collect())
        .collect();
    let (mut total, mut count, mut shadowed) = (0f64, 0f64, 0f64);
    for (s, units) in strata.iter().zip(&sums).filter(|(_, u)| !u.is_empty()) {
        let w = s.population as f64 / units.len() as f64;
        for &(y, x) in units {
            total += w * y;
            count += w * x;
            shadowed += x;
        }
    }
    if shadowed == 0.0 {
        return (0.0, 0.0, 1.0, 0);
    }
    let e = total / count;
    let mut var = 0f64;
    for (s, units) in strata.iter().zip(&sums).filter(|(_, u)| u.len() > 1) {
        let n = units.len() as f64;
        let big_n = s.population as f64;
        let d: Vec<f64> = units.iter().map(|&(y, x)| y - e * x).collect();
        let mean = d.iter().sum::<f64>() / n;
        let var_d = d.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
        var += big_n * big_n * (1.0 - n / big_n).max(0.0) * var_d / n;
    }
    let half = 1.96 * var.sqrt() / count;
    (
        e,
        (e - half).max(0.0),
        (e + half).min(1.0),
        shadowed as usize,
    )
}

/// The units to trace, in order, as (stratum, unit): of `shadow` units in
/// the result's shadow and `lit` others, `total` in all, `shadow_share` of
/// them in the shadow where both strata have enough, drawn at random
/// (seeds 1 and 2) and interleaved three to one so that any prefix keeps
/// the strata's shares (a timed draw stops after any batch).
pub fn strata_order(
    (shadow, lit): (&[usize], &[usize]),
    total: usize,
    shadow_share: f64,
) -> Vec<(usize, usize)> {
    let want0 = ((total as f64 * shadow_share).round() as usize).min(shadow.len());
    let want1 = (total - want0).min(lit.len());
    let want0 = (total - want1).min(shadow.len());
    let (d0, d1) = (draw(shadow.len(), want0, 1), draw(lit.len(), want1, 2));
    let mut order: Vec<(usize, usize)> = Vec::with_capacity(total);
    let (mut i0, mut i1) = (0, 0);
    while i0 < d0.len() || i1 < d1.len() {
        let take_shadow = i1 >= d1.len() || (i0 < d0.len() && i0 <= 3 * i1 + 2);
        if take_shadow {
            order.push((0, shadow[d0[i0]]));
            i0 += 1;
        } else {
            order.push((1, lit[d1[i1]]));
            i1 += 1;
        }
    }
    order
}

/// Adds a traced batch to `strata`: its (stratum, unit) pairs, `units[u]`
/// the unit's indices into `result`, and `exact` the exact visibilities of
/// the batch's pixels in the same order.
pub fn add_batch(
    strata: &mut [Stratum],
    batch: &[(usize, usize)],
    units: &[&[usize]],
    result: &[f32],
    exact: &[f32],
) {
    let mut at = 0;
    for &(h, u) in batch {
        let pairs = units[u]
            .iter()
            .zip(&exact[at..])
            .map(|(&k, &r)| (result[k], r))
            .collect();
        at += units[u].len();
        strata[h].drawn.push(pairs);
    }
}

/// The estimate from `strata`, `traced` pixels with `samples` light
/// samples each, begun at `t0`.
pub fn finish(
    strata: &[Stratum],
    traced: usize,
    samples: u32,
    t0: std::time::Instant,
) -> ErrorEstimate {
    let (error, low, high, shadowed) = ratio_estimate(strata);
    ErrorEstimate {
        error,
        low,
        high,
        traced,
        shadowed,
        samples,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// The first `k` of a random permutation of `0..n` (partial Fisher–Yates),
/// the same for the same `seed`: a longer draw extends a shorter one.
pub fn draw(n: usize, k: usize, seed: u64) -> Vec<usize> {
    let k = k.min(n);
    let mut state = seed;
    let mut next = || {
        // SplitMix64.
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    // Only the touched positions of the identity permutation are stored.
    let mut moved = std::collections::HashMap::with_capacity(2 * k);
    let mut out = Vec::with_capacity(k);
    for i in 0..k {
        let j = i + (next() % (n - i) as u64) as usize;
        let at_j = *moved.get(&j).unwrap_or(&j);
        let at_i = *moved.get(&i).unwrap_or(&i);
        moved.insert(j, at_i);
        out.push(at_j);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drawing_everything_gives_the_exact_error_and_no_width() {
        // Every pixel drawn: the estimate is the metric itself.
        let pixels: Vec<(f32, f32)> = (0..100)
            .map(|i| (i as f32 / 100.0, if i < 40 { 0.5 } else { 1.0 }))
            .collect();
        let truth = pixels[..40]
            .iter()
            .map(|&(v, r)| (v as f64 - r as f64).abs())
            .sum::<f64>()
            / 40.0;
        let s = Stratum {
            population: 100,
            drawn: pixels.iter().map(|&p| vec![p]).collect(),
        };
        let (e, lo, hi, n) = ratio_estimate(&[s]);
        assert!((e - truth).abs() < 1e-12 && n == 40);
        assert!((hi - lo) < 1e-12, "{lo} {hi}");
    }

    /// How many of 200 draws' intervals hold the true error: a shadowed
    /// stratum (|ΔV| spread over [0, 0.1]) and a lit one in which one pixel
    /// in `every` is a missed shadow of error 0.3.
    fn coverage(every: usize) -> u32 {
        let n1 = 5000;
        let n0 = 20000;
        let shadow: Vec<(f32, f32)> = (0..n1)
            .map(|i| (0.5 + 0.1 * ((i * 7919) % n1) as f32 / n1 as f32, 0.5))
            .collect();
        let lit: Vec<(f32, f32)> = (0..n0)
            .map(|i| {
                if i % every == 0 {
                    (1.0, 0.7)
                } else {
                    (1.0, 1.0)
                }
            })
            .collect();
        let missed = lit.iter().filter(|p| p.1 < 0.999).count();
        let truth = (shadow.iter().chain(&lit))
            .filter(|p| p.1 < 0.999)
            .map(|&(v, r)| (v as f64 - r as f64).abs())
            .sum::<f64>()
            / (n1 + missed) as f64;
        let mut covered = 0;
        for seed in 0..200u64 {
            let pick = |pop: &[(f32, f32)], k: usize, s: u64| Stratum {
                population: pop.len(),
                drawn: draw(pop.len(), k, s)
                    .iter()
                    .map(|&i| vec![pop[i]])
                    .collect(),
            };
            let strata = [pick(&shadow, 300, seed), pick(&lit, 100, seed + 1000)];
            let (_, lo, hi, _) = ratio_estimate(&strata);
            covered += (lo <= truth && truth <= hi) as u32;
        }
        covered
    }

    #[test]
    fn the_interval_covers_the_truth_about_95_times_in_100() {
        // Missed shadows common enough to be drawn (1 lit pixel in 5):
        // the normal approximation holds.
        let c = coverage(5);
        assert!((180..=199).contains(&c), "{c} of 200");
        // Rare ones (1 in 50, two expected among the 100 lit pixels drawn):
        // the skew makes the interval too narrow, measured 170 of 200. A
        // known limit of the normal interval (docs/accuracy.md).
        let c = coverage(50);
        assert!((160..=190).contains(&c), "{c} of 200");
    }

    #[test]
    fn units_of_several_pixels_weigh_by_their_shadowed_pixels() {
        // Two units drawn of two: the error is the pixel mean, not the
        // mean of unit means.
        let s = Stratum {
            population: 2,
            drawn: vec![
                vec![(0.6, 0.5), (1.0, 1.0)],
                vec![(0.2, 0.0), (0.4, 0.0), (0.0, 0.0)],
            ],
        };
        let (e, lo, hi, n) = ratio_estimate(&[s]);
        assert!((e - (0.1 + 0.2 + 0.4) / 4.0).abs() < 1e-7, "{e}");
        assert_eq!(n, 4);
        assert!(hi - lo < 1e-12);
    }

    #[test]
    fn no_shadowed_sample_knows_nothing() {
        let s = Stratum {
            population: 10,
            drawn: vec![vec![(1.0, 1.0); 3]; 5],
        };
        assert_eq!(ratio_estimate(&[s]), (0.0, 0.0, 1.0, 0));
        assert_eq!(ratio_estimate(&[]), (0.0, 0.0, 1.0, 0));
    }

    #[test]
    fn draws_are_distinct_deterministic_and_extend() {
        let a = draw(1000, 100, 7);
        let b = draw(1000, 300, 7);
        assert_eq!(a[..], b[..100]);
        let mut c = b.clone();
        c.sort_unstable();
        c.dedup();
        assert_eq!(c.len(), 300);
        assert!(b.iter().all(|&i| i < 1000));
        assert_eq!(draw(5, 10, 1).len(), 5);
        assert!(draw(0, 3, 1).is_empty());
        assert_ne!(draw(1000, 100, 8), a);
    }
}
