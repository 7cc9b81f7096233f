//! Walker's alias method: a draw from `n` weighted cells in constant time, one table lookup
//! and one comparison, where inverting a cumulative sum takes a binary search (and, over a
//! large map, a cache miss per step). Built by Vose's algorithm.
//!
//! Cell `i` is kept when the draw's second number falls below `threshold[i]` and gives way
//! to `alias[i]` otherwise, so cell `i` is drawn with probability
//! `(threshold[i] + sum over j with alias[j] = i of (1 - threshold[j])) / n = w[i] / sum w`.
//!
//! [`GroupedAliasTable`] draws in two levels, a group of consecutive cells (an environment
//! map's row) and then a cell of it, each by alias: the same probabilities, but where the one
//! table's draw reads a slot anywhere in it (over a map of megabytes, a cache miss per draw,
//! whatever the cell drawn), the grouped one reads the groups' small table, which stays in
//! cache, and then a slot of the drawn group, which stays in cache when the draws favour a
//! few groups (the sun's rows of a sky).

use rayon::prelude::*;

/// One cell of an [`AliasTable`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    /// The probability of keeping this cell once it is picked.
    threshold: f32,
    /// The cell drawn instead.
    alias: u32,
}

impl Entry {
    /// A slot that keeps its cell whatever the draw: a threshold of 1 is above every number
    /// a draw compares with it (at most `1 - 2^-24`), so its alias is never read.
    const KEPT: Self = Self {
        threshold: 1.0,
        alias: 0,
    };
}

/// Writes the alias table of `weights` by Vose's algorithm into `entries`, each
/// [`Entry::KEPT`] on entry (only the slots that give way are written), the cells numbered
/// from `first`; the weights' sum, or `None` when there are no weights or one is negative or
/// not finite, or their sum is not. All-zero weights draw every cell alike (as
/// [`super::Distribution1D`] does).
fn fill(weights: &[f64], first: u32, entries: &mut [Entry]) -> Option<f64> {
    debug_assert_eq!(weights.len(), entries.len(), "an entry a weight");
    let total = super::weights_total(weights)?;
    let n = weights.len() as f64;
    let mut scaled: Vec<f64> = if total > 0.0 {
        weights.iter().map(|w| w * n / total).collect()
    } else {
        vec![1.0; weights.len()]
    };
    let (mut small, mut large): (Vec<u32>, Vec<u32>) =
        (0..weights.len() as u32).partition(|&i| scaled[i as usize] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        entries[s as usize] = Entry {
            threshold: scaled[s as usize] as f32,
            alias: first + l,
        };
        // The large cell gives what the small one lacks, and may become small itself.
        scaled[l as usize] -= 1.0 - scaled[s as usize];
        if scaled[l as usize] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What remains on either list is 1 up to rounding: kept whole, as it came.
    Some(total)
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
        if u32::try_from(weights.len()).is_err() {
            return None;
        }
        let mut entries = vec![Entry::KEPT; weights.len()];
        fill(weights, 0, &mut entries)?;
        Some(Self { entries })
    }

    /// The number of cells.
    #[must_use]
    pub fn cells(&self) -> usize {
        self.entries.len()
    }

    /// The cell for 32 uniform bits: their product with the number of cells picks a slot
    /// (its whole part) and keeps it or takes its alias (its fraction, 24 bits of it).
    #[must_use]
    #[inline]
    pub fn sample(&self, bits: u32) -> usize {
        draw(&self.entries, 0, bits)
    }
}

/// The cell `entries` (the slots from `first` on) draw for 32 uniform bits: the slot or its
/// alias chosen by a conditional move, not a branch (random, and mispredicted as often as
/// not; a mask of the two is turned back into a branch by the compiler).
#[inline]
fn draw(entries: &[Entry], first: usize, bits: u32) -> usize {
    let wide = u64::from(bits) * entries.len() as u64;
    let slot = (wide >> 32) as usize;
    let keep = super::unit_f32(wide as u32);
    let entry = entries[slot];
    core::hint::select_unpredictable(keep < entry.threshold, first + slot, entry.alias as usize)
}

/// An [`AliasTable`] over groups of `group` consecutive cells, then one per group (see the
/// module's documentation): the same draw's probabilities, fewer cache misses.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupedAliasTable {
    groups: AliasTable,
    /// Each group's table in turn, its aliases the cells' own indices.
    cells: Vec<Entry>,
    group: usize,
    total: f64,
}

impl GroupedAliasTable {
    /// The table of these weights in groups of `group` (which divides their number), or
    /// `None` where it does not or [`AliasTable::new`] refuses them. All-zero weights draw
    /// every cell alike.
    #[must_use]
    pub fn new(weights: &[f64], group: usize) -> Option<Self> {
        if group == 0 || !weights.len().is_multiple_of(group) {
            return None;
        }
        Self::from_groups(weights.len() / group, group, |index, out| {
            out.copy_from_slice(&weights[index * group..][..group]);
        })
    }

    /// The table of `groups` groups of `group` cells, group `index`'s weights written into
    /// its slice by `weights_of(index, slice)`: the weights are made a group at a time on
    /// each thread, never all at once (a map's would be megabytes, made and thrown away).
    /// `None` where there are no cells, more than `u32::MAX`, or [`AliasTable::new`]
    /// refuses a group's weights or their sums.
    #[must_use]
    pub fn from_groups(
        groups: usize,
        group: usize,
        weights_of: impl Fn(usize, &mut [f64]) + Sync,
    ) -> Option<Self> {
        let count = groups.checked_mul(group)?;
        if count == 0 || u32::try_from(count).is_err() {
            return None;
        }
        // The groups' tables are independent: built side by side, each from its weights.
        // Set on every thread, not by this one alone: the first touch of each page of
        // megabytes is the kernel's work too.
        let mut cells = Vec::with_capacity(count);
        cells.par_extend(rayon::iter::repeat_n(Entry::KEPT, count));
        let sums = cells
            .par_chunks_mut(group)
            .enumerate()
            .map_init(
                || vec![0.0; group],
                |weights, (index, cells)| {
                    weights_of(index, weights);
                    fill(weights, (index * group) as u32, cells)
                },
            )
            .collect::<Option<Vec<f64>>>()?;
        // Checked as a whole: a sum that overflows is refused, not its parts'.
        let total = sums.iter().sum::<f64>();
        if !total.is_finite() {
            return None;
        }
        Some(Self {
            groups: AliasTable::new(&sums)?,
            cells,
            group,
            total,
        })
    }

    /// The sum of the weights: the groups' sums, added in order.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The cell for 64 uniform bits: the high 32 draw the group, the low 32 the cell in it
    /// (each as [`AliasTable::sample`]).
    #[must_use]
    #[inline]
    pub fn sample(&self, bits: u64) -> usize {
        let (group, cell) = self.sample_in_group(bits);
        group * self.group + cell
    }

    /// [`GroupedAliasTable::sample`]'s cell as its group and its place in the group (an
    /// environment map's row and column, without a division).
    #[must_use]
    #[inline]
    pub fn sample_in_group(&self, bits: u64) -> (usize, usize) {
        let group = self.group_of(bits);
        (group, self.place_in(group, bits))
    }

    /// The group [`GroupedAliasTable::sample`] draws for these bits (their high 32).
    #[must_use]
    #[inline]
    pub fn group_of(&self, bits: u64) -> usize {
        self.groups.sample((bits >> 32) as u32)
    }

    /// The place in `group` (the one [`GroupedAliasTable::group_of`] drew for these bits)
    /// that [`GroupedAliasTable::sample`] draws: a caller that asked for the slot's line
    /// ([`GroupedAliasTable::prefetch`]) keeps the group rather than draw it twice.
    #[must_use]
    #[inline]
    pub fn place_in(&self, group: usize, bits: u64) -> usize {
        let first = group * self.group;
        let cells = &self.cells[first..first + self.group];
        draw(cells, first, bits as u32) - first
    }

    /// Asks for the cache line [`GroupedAliasTable::place_in`] will read in `group` for
    /// these bits (the groups' table is small enough to stay in cache).
    #[inline]
    pub fn prefetch(&self, group: usize, bits: u64, prefetch: crate::simd::Prefetch) {
        let slot = ((u64::from(bits as u32) * self.group as u64) >> 32) as usize;
        if let Some(entry) = self.cells.get(group * self.group + slot) {
            prefetch.line(entry);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The probability the table draws each cell with, from its entries: what a draw
    /// keeps, plus what every slot aliased to it gives away.
    fn probabilities(table: &AliasTable) -> Vec<f64> {
        slot_probabilities(&table.entries, 0, table.entries.len())
    }

    /// The same for the slots `entries` (the cells from `first` on) among `cells`.
    fn slot_probabilities(entries: &[Entry], first: usize, cells: usize) -> Vec<f64> {
        let n = entries.len() as f64;
        let mut p = vec![0.0; cells];
        for (i, entry) in entries.iter().enumerate() {
            let kept = f64::from(entry.threshold).min(1.0);
            p[first + i] += kept / n;
            p[entry.alias as usize] += (1.0 - kept) / n;
        }
        p
    }

    /// Weights of every kind: zeros, a range of sizes, one cell far above the rest.
    fn weights() -> Vec<f64> {
        (0..1000)
            .map(|i| match i % 7 {
                0 => 0.0,
                k => f64::from(k * k) * (1.0 + f64::from(i) / 100.0),
            })
            .chain([5e4, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0])
            .collect()
    }

    /// In two levels each cell is drawn with its group's probability times its own in the
    /// group: its weight over the total; and a zero-weight cell never, whatever the bits.
    #[test]
    fn grouped_cells_are_drawn_in_proportion_to_their_weights() {
        let weights = weights();
        let total: f64 = weights.iter().sum();
        let group = 12;
        let table = GroupedAliasTable::new(&weights, group).unwrap();
        assert!((table.total() - total).abs() <= 1e-12 * total);
        let groups = probabilities(&table.groups);
        let mut p = vec![0.0; weights.len()];
        for (g, chunk) in table.cells.chunks(group).enumerate() {
            let within = slot_probabilities(chunk, g * group, weights.len());
            for (p, q) in p.iter_mut().zip(within) {
                *p += groups[g] * q;
            }
        }
        for (i, (p, w)) in p.iter().zip(&weights).enumerate() {
            assert!(
                (p - w / total).abs() < 1e-7,
                "cell {i}: {p} against {}",
                w / total
            );
        }
        let mut drawn = vec![0u32; weights.len()];
        for k in 0..200_000_u64 {
            let bits = k.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (k << 17);
            let cell = table.sample(bits);
            assert!(weights[cell] > 0.0, "bits {bits:x} drew {cell}");
            drawn[cell] += 1;
        }
        // The heaviest cell's share of the draws, within 5 binomial sigmas.
        let (heaviest, share) = (1000, 5e4 / total);
        let sigma = (share * (1.0 - share) / 200_000.0).sqrt();
        let seen = f64::from(drawn[heaviest]) / 200_000.0;
        assert!((seen - share).abs() < 5.0 * sigma, "{seen} against {share}");
        assert!(GroupedAliasTable::new(&weights, 5).is_none());
        assert!(GroupedAliasTable::new(&weights, 0).is_none());
        // What the one table refuses, the grouped one refuses: a NaN, a negative weight in a
        // group whose sum is positive, a sum that overflows only across groups, no weights.
        for bad in [
            vec![1.0, f64::NAN, 1.0, 1.0],
            vec![1.0, 3.0, -1.0, 1.0],
            vec![f64::MAX, 0.0, f64::MAX, 0.0],
            vec![],
        ] {
            assert!(GroupedAliasTable::new(&bad, 2).is_none(), "{bad:?}");
        }
    }

    #[test]
    fn each_cell_is_drawn_in_proportion_to_its_weight() {
        let weights = weights();
        let total: f64 = weights.iter().sum();
        let table = AliasTable::new(&weights).unwrap();
        for (i, (p, w)) in probabilities(&table).iter().zip(&weights).enumerate() {
            assert!(
                (p - w / total).abs() < 1e-7,
                "cell {i}: {p} against {}",
                w / total
            );
        }
        // A zero-weight cell is never drawn, whatever the numbers: each slot's first,
        // middle and last bits.
        let n = weights.len() as u64;
        for slot in 0..n {
            let first = (slot << 32).div_ceil(n);
            let last = (((slot + 1) << 32) - 1) / n;
            for bits in [first, (first + last) / 2, last] {
                let cell = table.sample(bits as u32);
                assert!(weights[cell] > 0.0, "slot {slot} bits {bits} drew {cell}");
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
