//! The one statistic several stages share: a median, where a mean would follow the outliers
//! (a prior's triangulation angles, a model's spread, a pair's transfer errors, a run's pose
//! errors).

/// The median of `values`: the upper one of an even count, so that it is always one of the
/// values; `None` for no values (each caller says what that means for it).
pub fn median(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = values.into_iter().collect();
    if v.is_empty() {
        return None;
    }
    let mid = v.len() / 2;
    Some(*v.select_nth_unstable_by(mid, f64::total_cmp).1)
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn median_of_odd_and_even_counts_and_of_none() {
        assert_eq!(median([3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median([4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(median([2.0, f64::INFINITY, 1.0]), Some(2.0));
        assert_eq!(median([]), None);
    }
}
