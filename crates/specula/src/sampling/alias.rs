//! Walker's alias method: a draw from `n` weighted cells in constant time, one table lookup
//! and one comparison, where inverting a cumulative sum takes a binary search (and, over a
//! large map, a cache miss per step). Built by Vose's algorithm.
//!
//! Cell `i` is kept when the draw's second number falls below `threshold[i]` and gives way
//! to `alias[i]` otherwise, so cell `i` is drawn with probability
//! `(threshold[i] + sum over j with alias[j] = i of (1 - threshold[j])) / n = w[i] / sum w`.

/// One cell of an [`AliasTable`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    /// The probability of keeping this cell once it is picked.
    threshold: f32,
    /// The cell drawn instead.
    alias: u32,
}

/// A table drawing cells in proportion to their weights in constant time.
#[derive(Clone, Debug, PartialEq)]
pub struct AliasTable {
    entries: Vec<Entry>,
}

impl AliasTable {
    /// The table of these weights, or `None` when there are none, more than `u32::MAX`, or
    /// one is negative or not finite. All-zero weights draw every cell alike (as
    /// [`super::Distribution1D`] does).
    #[must_use]
    pub fn new(weights: &[f64]) -> Option<Self> {
        if weights.is_empty()
            || u32::try_from(weights.len()).is_err()
            || weights.iter().any(|w| !w.is_finite() || *w < 0.0)
        {
            return None;
        }
        let total: f64 = weights.iter().sum();
        if !total.is_finite() {
            return None;
        }
        let n = weights.len() as f64;
        let mut scaled: Vec<f64> = if total > 0.0 {
            weights.iter().map(|w| w * n / total).collect()
        } else {
            vec![1.0; weights.len()]
        };
        let mut entries: Vec<Entry> = (0..weights.len() as u32)
            .map(|i| Entry {
                threshold: 1.0,
                alias: i,
            })
            .collect();
        let (mut small, mut large): (Vec<u32>, Vec<u32>) =
            (0..weights.len() as u32).partition(|&i| scaled[i as usize] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            entries[s as usize] = Entry {
                threshold: scaled[s as usize] as f32,
                alias: l,
            };
            // The large cell gives what the small one lacks, and may become small itself.
            scaled[l as usize] -= 1.0 - scaled[s as usize];
            if scaled[l as usize] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What remains on either list is 1 up to rounding: kept whole (threshold 1).
        Some(Self { entries })
    }

    /// The number of cells.
    #[must_use]
    pub fn cells(&self) -> usize {
        self.entries.len()
    }

    /// The cell for 32 uniform bits (which pick a slot) and a uniform number in `[0, 1)`
    /// (which keeps it or takes its alias).
    #[must_use]
    #[inline]
    pub fn sample(&self, bits: u32, keep: f32) -> usize {
        let slot = ((u64::from(bits) * self.entries.len() as u64) >> 32) as usize;
        let entry = self.entries[slot];
        if keep < entry.threshold {
            slot
        } else {
            entry.alias as usize
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The probability the table draws each cell with, from its entries: what a draw
    /// keeps, plus what every slot aliased to it gives away.
    fn probabilities(table: &AliasTable) -> Vec<f64> {
        let n = table.entries.len() as f64;
        let mut p = vec![0.0; table.entries.len()];
        for (i, entry) in table.entries.iter().enumerate() {
            let kept = f64::from(entry.threshold).min(1.0);
            p[i] += kept / n;
            p[entry.alias as usize] += (1.0 - kept) / n;
        }
        p
    }

    #[test]
    fn each_cell_is_drawn_in_proportion_to_its_weight() {
        let weights: Vec<f64> = (0..1000)
            .map(|i| match i % 7 {
                0 => 0.0,
                k => f64::from(k * k) * (1.0 + f64::from(i) / 100.0),
            })
            .chain([5e4])
            .collect();
        let total: f64 = weights.iter().sum();
        let table = AliasTable::new(&weights).unwrap();
        for (i, (p, w)) in probabilities(&table).iter().zip(&weights).enumerate() {
            assert!(
                (p - w / total).abs() < 1e-7,
                "cell {i}: {p} against {}",
                w / total
            );
        }
        // A zero-weight cell is never drawn, whatever the numbers.
        for slot in 0..weights.len() as u64 {
            let bits = ((slot << 32) / weights.len() as u64 + 1) as u32;
            for keep in [0.0, 0.5, 0.999_999] {
                let cell = table.sample(bits, keep);
                assert!(weights[cell] > 0.0, "slot {slot} keep {keep} drew {cell}");
            }
        }
    }

    #[test]
    fn degenerate_weights_are_uniform_or_refused() {
        let table = AliasTable::new(&[0.0, 0.0, 0.0]).unwrap();
        assert!(probabilities(&table)
            .iter()
            .all(|p| (p - 1.0 / 3.0).abs() < 1e-12));
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[1.0, f64::NAN]).is_none());
        assert!(AliasTable::new(&[1.0, -1.0]).is_none());
        assert!(AliasTable::new(&[f64::MAX, f64::MAX]).is_none());
    }
}
