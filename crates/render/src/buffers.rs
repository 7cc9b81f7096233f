//! Buffers of megabytes made ready on every thread.

use rayon::prelude::*;

/// `len` copies of `value`, written on every thread. `vec![value; len]` writes them on the
/// calling thread alone (only zeros of plain numbers come from `calloc`, untouched), and the
/// first touch of each page is the kernel's work too: about 1.35 us a page here, a
/// millisecond and more a buffer the size of a frame's G-buffer or a sky map.
#[must_use]
pub(crate) fn filled<T: Clone + Send + Sync>(value: T, len: usize) -> Vec<T> {
    let mut buffer = Vec::with_capacity(len);
    buffer.par_extend(rayon::iter::repeat_n(value, len));
    buffer
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_element_is_the_value() {
        for len in [0, 1, 4095, 1 << 20] {
            let buffer = filled((1.5_f32, 7_u32), len);
            assert_eq!(buffer.len(), len);
            assert!(buffer.iter().all(|&element| element == (1.5, 7)));
        }
    }
}
