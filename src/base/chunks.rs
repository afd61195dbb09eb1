//! A growing record kept in shared, fixed-size chunks: cloning it shares every chunk
//! (copy on write), so a snapshot of a long record costs a pointer per chunk instead of
//! a copy of the record. Appending to or truncating a shared record copies at most its
//! last chunk. Used for records a rendering hands over while the performance that made
//! them goes on (the drums' recorded membrane motion).

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
        for v in values {
            if self.len.is_multiple_of(self.chunk_len) {
                self.chunks
                    .push(Arc::new(Vec::with_capacity(self.chunk_len)));
            }
            let last = self.chunks.last_mut().expect("a chunk to append to");
            Arc::make_mut(last).push(v);
            self.len += 1;
        }
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

    /// A range across two chunks is refused rather than read wrong.
    #[test]
    #[should_panic(expected = "across two chunks")]
    fn a_range_across_chunks_panics() {
        let mut chunks = SharedChunks::new(4);
        chunks.extend(0..8);
        let _ = chunks.slice(3, 2);
    }
}
