//! What the equation-of-state study compares with, as plain functions: Henderson's and Liu's
//! equations for the hard-disk fluid, the 2D Maxwell–Boltzmann (Rayleigh) speed law and its
//! Kolmogorov–Smirnov distance, and block averages with their standard error.

/// Henderson's equation of state for the hard-disk fluid (Mol. Phys. 30, 971, 1975):
/// `Z = (1 + η²/8) / (1 − η)²` at area fraction `η`.
pub fn henderson_z(eta: f64) -> f64 {
    (1.0 + eta * eta / 8.0) / ((1.0 - eta) * (1.0 - eta))
}

/// Liu's equation of state for the stable hard-disk fluid (H. Liu, "Global equation of state
/// and phase transitions of the hard disc systems", arXiv:2010.10624, Eq. 1, as the author
/// gives it on SklogWiki): `Z = (1 + η²/8 + η³/18 − 4η⁴/21) / (1 − η)²`. Fitted to the fluid,
/// so meant up to about 0.65-0.70.
pub fn liu_z(eta: f64) -> f64 {
    let (e2, e3) = (eta * eta, eta * eta * eta);
    (1.0 + e2 / 8.0 + e3 / 18.0 - 4.0 * e2 * e2 / 21.0) / ((1.0 - eta) * (1.0 - eta))
}

/// The 2D Maxwell–Boltzmann speed distribution's cumulative probability at `speed`, for
/// `kt_over_m = kT/m`: `1 − exp(−v² / (2 kT/m))` (the Rayleigh law).
pub fn rayleigh_cdf(speed: f64, kt_over_m: f64) -> f64 {
    1.0 - (-speed * speed / (2.0 * kt_over_m)).exp()
}

/// Kolmogorov–Smirnov distance of `speeds` from the Rayleigh law with `kt_over_m`: the largest
/// gap between their empirical distribution and [`rayleigh_cdf`]. `None` for no speeds or a
/// value that is not a number.
pub fn rayleigh_ks(speeds: &[f64], kt_over_m: f64) -> Option<f64> {
    if speeds.is_empty()
        || speeds.iter().any(|v| v.is_nan())
        || kt_over_m.is_nan()
        || kt_over_m <= 0.0
    {
        return None;
    }
    let mut sorted = speeds.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len() as f64;
    let gap = sorted
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let f = rayleigh_cdf(v, kt_over_m);
            (f - i as f64 / n).abs().max(((i + 1) as f64 / n - f).abs())
        })
        .fold(0.0, f64::max);
    Some(gap)
}

/// The KS distance below which a sample of `n` independent draws is consistent with the law at
/// the 5 % level (large-`n` approximation `1.358 / √n`).
pub fn ks_critical_5_percent(n: usize) -> f64 {
    1.358 / (n as f64).sqrt()
}

/// Mean of `blocks` and the standard error of that mean (`s / √B`, with the sample standard
/// deviation `s`). `None` with fewer than two blocks.
pub fn block_mean(blocks: &[f64]) -> Option<(f64, f64)> {
    if blocks.len() < 2 {
        return None;
    }
    let b = blocks.len() as f64;
    let mean = blocks.iter().sum::<f64>() / b;
    let var = blocks.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (b - 1.0);
    Some((mean, (var / b).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fluid_equations_start_with_the_virial_series() {
        // Z = 1 + 2η + B3 η² + …, with B3 = 3.1280 for hard disks in these units.
        for z in [henderson_z, liu_z] {
            let eta = 1e-4;
            assert!(((z(eta) - 1.0) / eta - 2.0).abs() < 1e-3);
            let b3 = (z(eta) - 1.0 - 2.0 * eta) / (eta * eta);
            assert!((b3 - 3.128).abs() < 0.01, "B3 = {b3}");
        }
        // Liu lies a little below Henderson in the dense fluid, as simulations do.
        assert!(liu_z(0.6) < henderson_z(0.6));
        assert!((liu_z(0.6) / henderson_z(0.6) - 1.0).abs() < 0.02);
    }

    #[test]
    fn rayleigh_draws_pass_and_other_laws_fail() {
        // Inverse-CDF draws at evenly spaced quantiles are as close as a sample can be.
        let n = 1000;
        let draws: Vec<f64> = (0..n)
            .map(|i| (-2.0 * 0.5 * (1.0 - (i as f64 + 0.5) / n as f64).ln()).sqrt())
            .collect();
        let ks = rayleigh_ks(&draws, 0.5).unwrap();
        assert!(ks <= 0.5 / n as f64 + 1e-12, "{ks}");
        // All speeds equal (a fresh lattice's) is far from Rayleigh.
        let equal = vec![1.0; n];
        assert!(rayleigh_ks(&equal, 0.5).unwrap() > ks_critical_5_percent(n));
        assert_eq!(rayleigh_ks(&[], 0.5), None);
        assert_eq!(rayleigh_ks(&[f64::NAN], 0.5), None);
    }

    #[test]
    fn block_errors_are_the_standard_error_of_the_mean() {
        let (mean, err) = block_mean(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(mean, 2.5);
        assert!((err - (5.0f64 / 3.0 / 4.0).sqrt()).abs() < 1e-15);
        assert_eq!(block_mean(&[1.0]), None);
    }
}
