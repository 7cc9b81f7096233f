//! A volume's samples as the scan holds them: whole numbers within `i16`'s range (a CT in
//! Hounsfield units, most MRIs) as `i16`, exactly and in half the memory of `f32`; anything
//! else as `f32`. The choice is made from the values, never by the caller, so one set of
//! values always has one form (and volumes compare equal by value).

use std::borrow::Cow;
use std::sync::Arc;

/// A volume's samples, `i` fastest.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    /// Every sample a whole number in `[-32768, 32767]`. Shared: the prepared volume's
    /// compact layout reads its values from here rather than holding a copy.
    Whole(Arc<Vec<i16>>),
    /// Any other finite values.
    Float(Vec<f32>),
}

/// A sample type the volume's loops are written over once: `i16` or `f32`.
pub trait Sample: Copy + Into<f32> + Send + Sync + 'static {}

impl Sample for i16 {}
impl Sample for f32 {}

impl Samples {
    /// `values` in their form: as `i16` when every one is a whole number in its range.
    #[must_use]
    pub fn new(values: Vec<f32>) -> Self {
        let fits = |v: f32| v == v.trunc() && (-32_768.0..=32_767.0).contains(&v);
        if values.iter().all(|&v| fits(v)) {
            // Exact: each value is an integer `i16` holds.
            Samples::Whole(Arc::new(values.iter().map(|&v| v as i16).collect()))
        } else {
            Samples::Float(values)
        }
    }

    /// Integers as read from a file.
    #[must_use]
    pub fn whole(values: Vec<i16>) -> Self {
        Samples::Whole(Arc::new(values))
    }

    /// How many.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Samples::Whole(values) => values.len(),
            Samples::Float(values) => values.len(),
        }
    }

    /// Whether there are none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sample `index`.
    ///
    /// # Panics
    /// If `index` is out of bounds.
    #[inline]
    #[must_use]
    pub fn get(&self, index: usize) -> f32 {
        match self {
            Samples::Whole(values) => f32::from(values[index]),
            Samples::Float(values) => values[index],
        }
    }

    /// Every sample in order, as `f32`.
    pub fn iter(&self) -> impl Iterator<Item = f32> + '_ {
        let (whole, float): (&[i16], &[f32]) = match self {
            Samples::Whole(values) => (values, &[]),
            Samples::Float(values) => (&[], values),
        };
        whole
            .iter()
            .map(|&v| f32::from(v))
            .chain(float.iter().copied())
    }

    /// The samples as `f32`: borrowed when they are held so, else converted.
    #[must_use]
    pub fn to_f32(&self) -> Cow<'_, [f32]> {
        match self {
            Samples::Whole(values) => Cow::Owned(values.iter().map(|&v| f32::from(v)).collect()),
            Samples::Float(values) => Cow::Borrowed(values),
        }
    }

    /// Bytes each sample takes.
    #[must_use]
    pub fn bytes_per_sample(&self) -> usize {
        match self {
            Samples::Whole(_) => size_of::<i16>(),
            Samples::Float(_) => size_of::<f32>(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_numbers_in_range_are_held_as_integers_and_read_back_exactly() {
        let values = vec![-32_768.0, -1024.0, 0.0, 3071.0, 32_767.0];
        let samples = Samples::new(values.clone());
        assert!(matches!(samples, Samples::Whole(_)));
        assert_eq!(samples.bytes_per_sample(), 2);
        assert_eq!(samples.iter().collect::<Vec<_>>(), values);
        assert_eq!(samples.to_f32().as_ref(), values.as_slice());
        assert_eq!(samples.get(3), 3071.0);
        assert_eq!(
            samples,
            Samples::whole(vec![-32_768, -1024, 0, 3071, 32_767])
        );
    }

    #[test]
    fn fractions_and_values_beyond_i16_stay_f32() {
        for values in [vec![0.0, 0.5], vec![0.0, 32_768.0], vec![-32_769.0, 1.0]] {
            let samples = Samples::new(values.clone());
            assert!(matches!(samples, Samples::Float(_)), "{values:?}");
            assert_eq!(samples.iter().collect::<Vec<_>>(), values);
            assert_eq!(samples.len(), 2);
        }
    }
}
