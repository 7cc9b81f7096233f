//! The environment's draws made ahead of the shading, a run of pixels at a time.
//!
//! An environment draw reads two places of tables of megabytes, one after the other: the
//! alias entry its bits pick (which says the texel), then that texel's record. Drawn inside
//! a pixel's packet, both reads wait in turn, and a pixel of the full-frame close-up paid
//! about 200 ns for them whatever its samples. The draws do not depend on the surface, so a
//! row is taken a run of pixels at a time: first every draw's bits and the alias entry they
//! will read are asked for ([`LightCells::push`]), then every texel is drawn, its entry
//! arrived meanwhile, and its record asked for ([`LightCells::resolve`]); the packets then
//! take their texels in the order pushed ([`LightCells::take`]), their records in cache.

use specula::sampling::random_bits;
use specula::simd::Prefetch;

use super::Environment;

/// The texels of a run of environment draws, in the order their draws were pushed.
#[derive(Default)]
pub(super) struct LightCells {
    /// Each draw's random bits (dimension 0 of its draw), then the row they drew.
    bits: Vec<u64>,
    rows: Vec<u32>,
    /// The column drawn in the row, for the draws resolved.
    columns: Vec<u32>,
    /// How many draws the packets have taken.
    taken: usize,
}

impl LightCells {
    /// Forgets the draws pushed, keeping the room they took.
    pub(super) fn clear(&mut self) {
        self.bits.clear();
        self.rows.clear();
        self.columns.clear();
        self.taken = 0;
    }

    /// Adds `draws` (draw indices of the stream `seed`): their bits and the rows they draw,
    /// asking for the alias entries [`LightCells::resolve`] will read.
    pub(super) fn push(
        &mut self,
        environment: &Environment,
        seed: u64,
        draws: impl Iterator<Item = u64>,
    ) {
        let prefetch = Prefetch::new();
        for draw in draws {
            let bits = random_bits(seed, draw, 0);
            self.bits.push(bits);
            self.rows.push(environment.prefetch_draw(bits, prefetch));
        }
    }

    /// Draws the texel of every draw pushed since the last call, asking for its record.
    pub(super) fn resolve(&mut self, environment: &Environment) {
        let prefetch = Prefetch::new();
        for k in self.columns.len()..self.bits.len() {
            let (row, column) = (
                self.rows[k],
                environment.draw_column(self.rows[k], self.bits[k]),
            );
            self.columns.push(column);
            environment.prefetch_texel(environment.texel(row, column), prefetch);
        }
    }

    /// The rows and columns of the next `count` draws resolved, in the order pushed.
    ///
    /// # Panics
    /// If fewer than `count` draws are left resolved: a packet takes the draws pushed for it.
    pub(super) fn take(&mut self, count: usize) -> (&[u32], &[u32]) {
        let range = self.taken..self.taken + count;
        self.taken += count;
        (&self.rows[range.clone()], &self.columns[range])
    }
}
