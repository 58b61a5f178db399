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

/// Pairs of distinct grains with circles closer than `gap` (surface to surface; overlapping
/// circles count). `circles[k] = (grain, [x, y, r])`. A uniform cell grid makes it O(n).
pub fn near_pairs(circles: &[(usize, [f64; 3])], gap: f64) -> Vec<(usize, usize)> {
    if circles.is_empty() {
        return Vec::new();
    }
    let rmax = circles.iter().map(|c| c.1[2]).fold(0.0, f64::max);
    let cell = (2.0 * rmax + gap).max(f64::MIN_POSITIVE);
    let (x0, y0) = circles.iter().fold((f64::INFINITY, f64::INFINITY), |(a, b), c| {
        (a.min(c.1[0]), b.min(c.1[1]))
    });
    let key = |c: &[f64; 3]| (((c[0] - x0) / cell) as i64, ((c[1] - y0) / cell) as i64);
    let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> = std::collections::HashMap::new();
    for (k, c) in circles.iter().enumerate() {
        cells.entry(key(&c.1)).or_default().push(k);
    }
    let mut out = std::collections::BTreeSet::new();
    for (k, (gk, c)) in circles.iter().enumerate() {
        let (cx, cy) = key(c);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &m in cells.get(&(cx + dx, cy + dy)).map_or(&[][..], |v| v.as_slice()) {
                    let (gm, d) = circles[m];
                    if m <= k || gm == *gk {
                        continue;
                    }
                    let dist = (c[0] - d[0]).hypot(c[1] - d[1]);
                    if dist - c[2] - d[2] < gap {
                        out.insert((*gk.min(&gm), *gk.max(&gm)));
                    }
                }
            }
        }
    }
    out.into_iter().collect()
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

    #[test]
    fn near_pairs_finds_gaps_below_the_tolerance_and_skips_circles_of_one_grain() {
        let c = [
            (0, [0.0, 0.0, 1.0]),
            (0, [1.0, 0.0, 1.0]),
            (1, [3.05, 0.0, 1.0]),
            (2, [5.2, 0.0, 1.0]),
            (3, [0.0, 2.0, 1.0]),
        ];
        // Grain 0-1 gap 0.05, 1-2 gap 0.15, 0-3 touching.
        assert_eq!(near_pairs(&c, 0.1), vec![(0, 1), (0, 3)]);
        assert_eq!(near_pairs(&c, 0.2), vec![(0, 1), (0, 3), (1, 2)]);
        assert!(near_pairs(&[], 0.1).is_empty());
    }
}
