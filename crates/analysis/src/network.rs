//! Whether the grains form a percolating network (Su et al. 2020 Sect. 3.1: below a critical
//! solid fraction "the grain assembly does not form a percolating network", the suspension
//! class). A network percolates here when one cluster of touching grains spans the sample along
//! the loading direction: it holds a grain within `reach` of the lowest grain edge and one within
//! `reach` of the highest. Clusters by union-find over the contact list of a snapshot.

use serde::Serialize;

/// What the contact network of a snapshot looks like.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Network {
    /// A cluster spans bottom to top.
    pub percolates: bool,
    /// Grains in the largest cluster, over all grains.
    pub largest_cluster_fraction: f64,
    /// Mean coordination number 2 × (distinct touching grain pairs) / grains.
    pub coordination: f64,
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The network of `n` grains with vertical extents `lo[k]..hi[k]` (m) touching in `pairs` (grain
/// indices; duplicates and self-pairs, e.g. circles of one clump, are ignored).
pub fn network(n: usize, lo: &[f64], hi: &[f64], pairs: &[(usize, usize)], reach: f64) -> Network {
    if n == 0 {
        return Network {
            percolates: false,
            largest_cluster_fraction: 0.0,
            coordination: 0.0,
        };
    }
    let mut parent: Vec<usize> = (0..n).collect();
    let mut seen = std::collections::BTreeSet::new();
    for &(a, b) in pairs {
        if a == b || a >= n || b >= n {
            continue;
        }
        seen.insert((a.min(b), a.max(b)));
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb);
        }
    }
    let bottom = lo.iter().copied().fold(f64::INFINITY, f64::min);
    let top = hi.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut size = vec![0usize; n];
    let mut touches_bottom = vec![false; n];
    let mut touches_top = vec![false; n];
    for k in 0..n {
        let r = find(&mut parent, k);
        size[r] += 1;
        touches_bottom[r] |= lo[k] <= bottom + reach;
        touches_top[r] |= hi[k] >= top - reach;
    }
    Network {
        percolates: (0..n).any(|r| size[r] > 1 && touches_bottom[r] && touches_top[r]),
        largest_cluster_fraction: *size.iter().max().unwrap_or(&0) as f64 / n as f64,
        coordination: 2.0 * seen.len() as f64 / n as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_percolates_and_a_broken_one_does_not() {
        // Five grains of height 1 stacked at y = 0, 1, 2, 3, 4.
        let lo: Vec<f64> = (0..5).map(|k| k as f64).collect();
        let hi: Vec<f64> = lo.iter().map(|y| y + 1.0).collect();
        let chain = [(0, 1), (1, 2), (2, 3), (3, 4), (1, 0), (2, 2)];
        let n = network(5, &lo, &hi, &chain, 0.5);
        assert!(n.percolates);
        assert_eq!(n.largest_cluster_fraction, 1.0);
        assert!((n.coordination - 2.0 * 4.0 / 5.0).abs() < 1e-15);
        let broken = [(0, 1), (2, 3), (3, 4)];
        let n = network(5, &lo, &hi, &broken, 0.5);
        assert!(!n.percolates);
        assert_eq!(n.largest_cluster_fraction, 0.6);
        assert!(!network(0, &[], &[], &[], 1.0).percolates);
    }
}
