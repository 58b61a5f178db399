//! Non-dominated settings: no other setting is both at least as accurate and at least as fast,
//! and strictly better in one of the two.

/// For each (error, cost) pair, whether no other pair dominates it. Pairs with a non-finite
/// value are never on the front and dominate nothing.
pub fn non_dominated(error: &[f64], cost: &[f64]) -> Vec<bool> {
    let ok = |k: usize| error[k].is_finite() && cost[k].is_finite();
    (0..error.len())
        .map(|i| {
            ok(i)
                && !(0..error.len()).any(|j| {
                    j != i
                        && ok(j)
                        && error[j] <= error[i]
                        && cost[j] <= cost[i]
                        && (error[j] < error[i] || cost[j] < cost[i])
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_the_cheapest_for_each_accuracy_and_drops_the_rest() {
        // (error, cost): a is cheapest, d most accurate, b between, c dominated by b, e is a
        // duplicate of b (neither dominates the other), f is not finite.
        let e = [0.5, 0.2, 0.3, 0.01, 0.2, f64::NAN];
        let c = [1.0, 2.0, 3.0, 10.0, 2.0, 0.1];
        assert_eq!(non_dominated(&e, &c), [true, true, false, true, true, false]);
    }

    #[test]
    fn a_point_better_in_both_leaves_one_on_the_front() {
        assert_eq!(non_dominated(&[0.1, 0.2], &[1.0, 2.0]), [true, false]);
        assert_eq!(non_dominated(&[], &[]), Vec::<bool>::new());
    }
}
