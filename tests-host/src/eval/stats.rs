//! The statistics every table of the host tools reports, defined once: a "median" or a
//! "p95" column means the same thing in every table of docs/.

/// The `q`-quantile by nearest rank: the smallest value with at least `q` of the values at
/// or below it (`q` in (0, 1]; the p95 of 20 values is the 19th). NaN when empty.
pub fn quantile(v: &[f64], q: f64) -> f64 {
    let mut a = v.to_vec();
    if a.is_empty() {
        return f64::NAN;
    }
    a.sort_by(f64::total_cmp);
    a[((q * a.len() as f64).ceil() as usize).clamp(1, a.len()) - 1]
}

/// [`quantile`] of the magnitudes (errors whose sign is reported apart).
pub fn abs_quantile(v: &[f64], q: f64) -> f64 {
    let a: Vec<f64> = v.iter().map(|x| x.abs()).collect();
    quantile(&a, q)
}

/// The median: the middle value, or the mean of the middle two for an even count. NaN when
/// empty.
pub fn median(v: &[f64]) -> f64 {
    let mut a = v.to_vec();
    a.sort_by(f64::total_cmp);
    match a.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => a[n / 2],
        n => (a[n / 2 - 1] + a[n / 2]) / 2.0,
    }
}

/// The `q`-quantile at the rounded index `round((n − 1)·q)`, 0 when empty: the definition
/// `gaitclip train` fits Lu's D universe with (its 5 % and 95 % points). Kept apart from
/// [`quantile`] because the shipped models' tables were fitted with it.
pub fn quantile_at_rounded_index(v: &[f64], q: f64) -> f64 {
    let mut a = v.to_vec();
    a.sort_by(f64::total_cmp);
    if a.is_empty() {
        return 0.0;
    }
    a[((a.len() - 1) as f64 * q).round() as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn definitions() {
        let v: Vec<f64> = (1..=20).map(f64::from).collect();
        assert_eq!(quantile(&v, 0.95), 19.0);
        assert_eq!(quantile(&v, 1.0), 20.0);
        assert_eq!(quantile(&v[..1], 0.5), 1.0);
        assert!(quantile(&[], 0.5).is_nan());
        assert_eq!(abs_quantile(&[-3.0, 1.0, 2.0], 1.0), 3.0);
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(quantile_at_rounded_index(&v, 0.05), 2.0);
        assert_eq!(quantile_at_rounded_index(&v, 0.95), 19.0);
    }
}
