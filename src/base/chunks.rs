//! A growing record kept in shared, fixed-size chunks: cloning it shares every chunk
//! (copy on write), so a snapshot of a long record costs a pointer per chunk instead of
//! a copy of the record. Appending to or truncating a shared record copies at most its
//! last chunk, and rewriting a range copies only the shared chunks it leaves partly as
//! they were. Used for records a rendering hands over while the performance that made
//! them goes on (the drums' recorded membrane motion) and for audio a rendering hands
//! to playback while the next one rewrites what changed.

use std::sync::Arc;

/// Values in chunks of `chunk_len`; every chunk but the last is full.
#[derive(Clone, Debug)]
pub struct SharedChunks<T> {
    chunks: Vec<Arc<Vec<T>>>,
    chunk_len: usize,
    len: usize,
}

impl<T: Clone> SharedChunks<T> {
    /// An empty record in chunks of `chunk_len` values (at least 1).
    pub fn new(chunk_len: usize) -> SharedChunks<T> {
        SharedChunks {
            chunks: Vec::new(),
            chunk_len: chunk_len.max(1),
            len: 0,
        }
    }

    /// Values held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it holds no value.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Append `values`, copying the last chunk first if another record shares it.
    pub fn extend(&mut self, values: impl IntoIterator<Item = T>) {
        let mut values = values.into_iter().peekable();
        while values.peek().is_some() {
            if self.len.is_multiple_of(self.chunk_len) {
                self.chunks
                    .push(Arc::new(Vec::with_capacity(self.chunk_len)));
            }
            let room = self.chunk_len - self.len % self.chunk_len;
            let last = Arc::make_mut(self.chunks.last_mut().expect("a chunk to append to"));
            let before = last.len();
            last.extend(values.by_ref().take(room));
            self.len += last.len() - before;
        }
    }

    /// Append `value` (see [`extend`](Self::extend)).
    pub fn push(&mut self, value: T) {
        self.extend(std::iter::once(value));
    }

    /// Keep the first `len` values (all of them when there are fewer).
    pub fn truncate(&mut self, len: usize) {
        if len >= self.len {
            return;
        }
        self.chunks.truncate(len.div_ceil(self.chunk_len));
        let rest = len % self.chunk_len;
        if rest > 0
            && let Some(last) = self.chunks.last_mut()
        {
            Arc::make_mut(last).truncate(rest);
        }
        self.len = len;
    }

    /// The `count` values from `start`, which must lie in one chunk (a record whose
    /// items are `k` values long keeps them whole with a chunk length a multiple of `k`).
    ///
    /// # Panics
    /// When the range is outside the record or spans two chunks.
    pub fn slice(&self, start: usize, count: usize) -> &[T] {
        assert!(start + count <= self.len, "range outside the record");
        let (chunk, at) = (start / self.chunk_len, start % self.chunk_len);
        if count == 0 {
            return &[];
        }
        assert!(at + count <= self.chunk_len, "range across two chunks");
        &self.chunks[chunk][at..at + count]
    }

    /// Every value in order.
    pub fn iter(&self) -> impl Iterator<Item = &T> {
        self.chunks.iter().flat_map(|c| c.iter())
    }

    /// `values` in chunks of `chunk_len`.
    pub fn from_vec(values: Vec<T>, chunk_len: usize) -> SharedChunks<T> {
        let chunk_len = chunk_len.max(1);
        SharedChunks {
            len: values.len(),
            chunks: values
                .chunks(chunk_len)
                .map(|c| Arc::new(c.to_vec()))
                .collect(),
            chunk_len,
        }
    }

    /// The value at `index`, if there is one.
    pub fn get(&self, index: usize) -> Option<&T> {
        (index < self.len).then(|| &self.chunks[index / self.chunk_len][index % self.chunk_len])
    }

    /// The chunks in order, as slices (every one but the last `chunk_len` long).
    pub fn chunks(&self) -> impl Iterator<Item = &[T]> {
        self.chunks.iter().map(|c| c.as_slice())
    }

    /// How many chunks, place for place, are the very ones `other` holds (shared, not
    /// copies).
    pub fn shared_chunks(&self, other: &SharedChunks<T>) -> usize {
        self.chunks
            .iter()
            .zip(&other.chunks)
            .filter(|(a, b)| Arc::ptr_eq(a, b))
            .count()
    }

    /// A copy of the values in `range`, which may span chunks.
    ///
    /// # Panics
    /// When the range is outside the record.
    pub fn to_vec_of(&self, range: std::ops::Range<usize>) -> Vec<T> {
        assert!(range.end <= self.len, "range outside the record");
        let mut out = Vec::with_capacity(range.len());
        let mut at = range.start;
        while at < range.end {
            let (chunk, offset) = (at / self.chunk_len, at % self.chunk_len);
            let take = (self.chunk_len - offset).min(range.end - at);
            out.extend_from_slice(&self.chunks[chunk][offset..offset + take]);
            at += take;
        }
        out
    }

    /// A copy of every value.
    pub fn to_vec(&self) -> Vec<T> {
        self.to_vec_of(0..self.len)
    }

    /// Make it `len` values long: cut, or padded with `value`.
    pub fn resize(&mut self, len: usize, value: T) {
        if len <= self.len {
            self.truncate(len);
        } else {
            self.extend(std::iter::repeat_n(value, len - self.len));
        }
    }

    /// Rewrite the values from `start` on with `f` of the values of `source` at the same
    /// places (`source` as long as the record): a shared chunk rewritten whole is made
    /// anew, one rewritten in part is copied first, the chunks before `start` stay
    /// shared.
    ///
    /// # Panics
    /// When `source` is not as long as the record.
    pub fn rewrite_from<S>(&mut self, start: usize, source: &[S], f: impl Fn(&S) -> T) {
        assert_eq!(source.len(), self.len, "a source as long as the record");
        let chunk_len = self.chunk_len;
        for (c, chunk) in self.chunks.iter_mut().enumerate().skip(start / chunk_len) {
            let first = c * chunk_len;
            let from = start.max(first);
            let end = (first + chunk_len).min(source.len());
            let rewritten = source[from..end].iter().map(&f);
            if from == first && Arc::get_mut(chunk).is_none() {
                *chunk = Arc::new(rewritten.collect());
            } else {
                let values = Arc::make_mut(chunk);
                for (v, new) in values[from - first..].iter_mut().zip(rewritten) {
                    *v = new;
                }
            }
        }
    }
}

impl<T: Clone> std::ops::Index<usize> for SharedChunks<T> {
    type Output = T;

    /// # Panics
    /// When `index` is outside the record.
    fn index(&self, index: usize) -> &T {
        self.get(index).expect("index outside the record")
    }
}

impl<T: PartialEq> PartialEq for SharedChunks<T> {
    fn eq(&self, other: &Self) -> bool {
        self.len == other.len
            && self
                .chunks
                .iter()
                .flat_map(|c| c.iter())
                .eq(other.chunks.iter().flat_map(|c| c.iter()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Appending, truncating and reading give what a plain vector gives, across chunk
    /// boundaries, and a clone shares the chunks until one of the two writes.
    #[test]
    fn behaves_as_a_vector_and_shares_until_written() {
        let mut chunks = SharedChunks::new(4);
        let mut plain = Vec::new();
        for round in 0..5u32 {
            let values: Vec<u32> = (0..7).map(|k| round * 10 + k).collect();
            chunks.extend(values.iter().copied());
            plain.extend(values);
            let keep = plain.len() - (round as usize % 3) * 2;
            chunks.truncate(keep);
            plain.truncate(keep);
            assert_eq!(chunks.len(), plain.len());
            assert!(chunks.iter().copied().eq(plain.iter().copied()));
        }
        for start in (0..plain.len() - 2).step_by(4) {
            assert_eq!(chunks.slice(start, 3), &plain[start..start + 3]);
        }
        let snapshot = chunks.clone();
        assert!(
            Arc::ptr_eq(&snapshot.chunks[0], &chunks.chunks[0]),
            "shared"
        );
        chunks.truncate(2);
        chunks.extend([99, 98]);
        assert!(snapshot.iter().copied().eq(plain.iter().copied()));
        assert_eq!(
            chunks.iter().copied().collect::<Vec<_>>(),
            [plain[0], plain[1], 99, 98]
        );
        assert_ne!(snapshot, chunks);
    }

    /// Rewriting from a point, resizing, indexing and copying ranges give what a plain
    /// vector gives; a rewrite leaves the chunks before its start shared with a clone
    /// and copies none it rewrites whole.
    #[test]
    fn rewrites_from_a_point_and_keeps_what_is_before_it_shared() {
        let plain_of = |n: usize| (0..n as u32).collect::<Vec<_>>();
        let mut plain = plain_of(23);
        let mut chunks = SharedChunks::from_vec(plain.clone(), 5);
        assert_eq!(chunks.to_vec(), plain);
        assert_eq!(chunks.chunks().count(), 5);
        let snapshot = chunks.clone();
        let source: Vec<u32> = (0..23).map(|k| 100 + k).collect();
        chunks.rewrite_from(7, &source, |v| v * 2);
        for (k, v) in plain.iter_mut().enumerate().skip(7) {
            *v = source[k] * 2;
        }
        assert_eq!(chunks.to_vec(), plain);
        assert_eq!(
            snapshot.to_vec(),
            plain_of(23),
            "the clone keeps its values"
        );
        assert_eq!(
            chunks.shared_chunks(&snapshot),
            1,
            "only the chunk before: shared"
        );
        assert!(
            !Arc::ptr_eq(&snapshot.chunks[1], &chunks.chunks[1]),
            "in part: copied"
        );
        assert!(
            !Arc::ptr_eq(&snapshot.chunks[2], &chunks.chunks[2]),
            "whole: made anew"
        );
        for range in [0..0, 3..4, 4..11, 0..23, 22..23] {
            assert_eq!(chunks.to_vec_of(range.clone()), plain[range]);
        }
        for k in [0, 4, 5, 22] {
            assert_eq!(chunks[k], plain[k]);
            assert_eq!(chunks.get(k), Some(&plain[k]));
        }
        assert_eq!(chunks.get(23), None);
        chunks.resize(30, 7);
        plain.resize(30, 7);
        assert_eq!(chunks.to_vec(), plain);
        chunks.resize(12, 0);
        plain.truncate(12);
        assert_eq!(chunks.to_vec(), plain);
        let source: Vec<u32> = (0..12).collect();
        chunks.rewrite_from(12, &source, |v| *v);
        assert_eq!(
            chunks.to_vec(),
            plain,
            "a rewrite from the end changes nothing"
        );
    }

    /// A range across two chunks is refused rather than read wrong.
    #[test]
    #[should_panic(expected = "across two chunks")]
    fn a_range_across_chunks_panics() {
        let mut chunks = SharedChunks::new(4);
        chunks.extend(0..8);
        let _ = chunks.slice(3, 2);
    }
}
