//! Small read-only tables packed into one storage buffer (the tracer's
//! behind its texture words), so that the passes with the most inputs (the photon tracer, the
//! mirror/glass pass) fit WebGPU's default of 8 storage buffers per shader
//! stage, the most a browser can be relied on to give.
//!
//! Each table starts at a word offset the pass passes in its uniforms; the
//! shader reads its records field by field with `tables.wgsl`'s helpers
//! (WGSL cannot view one buffer as arrays of several struct types).

use bytemuck::Pod;

use crate::wgsl::Module;

/// Word readers over a packed buffer. The includer defines
/// `fn table_word(at: u32) -> u32` over the buffer its tables are in.
pub static TABLES: Module = Module { name: "tables.wgsl", source: include_str!("tables.wgsl"), requires: &[] };

/// The texture words followed by tables, each starting on a 16-byte boundary.
pub struct PackedTables {
    pub words: Vec<u32>,
}

impl PackedTables {
    pub fn after(texture_words: Vec<u32>) -> Self {
        PackedTables { words: texture_words }
    }

    /// Appends `records` and returns the word offset of the first.
    pub fn push<T: Pod>(&mut self, records: &[T]) -> u32 {
        self.reserve(std::mem::size_of_val(records) / 4, bytemuck::cast_slice(records))
    }

    /// Room for `count` records of `T` written later (e.g. per dispatch),
    /// zeroed; returns the word offset of the first.
    pub fn reserve_for<T: Pod>(&mut self, count: usize) -> u32 {
        self.reserve_words(count * std::mem::size_of::<T>() / 4)
    }

    /// Room for `words` zero words written later (e.g. copied in on the
    /// GPU); returns the word offset of the first.
    pub fn reserve_words(&mut self, words: usize) -> u32 {
        self.reserve(words, &[])
    }

    fn reserve(&mut self, words: usize, contents: &[u32]) -> u32 {
        self.words.resize(self.words.len().next_multiple_of(4), 0);
        let at = self.words.len();
        self.words.extend_from_slice(contents);
        self.words.resize(at + words, 0);
        at as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_start_aligned_after_the_textures() {
        let mut tables = PackedTables::after(vec![7; 5]);
        let a = tables.push(&[[1.0f32, 2.0, 3.0]]);
        let b = tables.reserve_for::<[u32; 4]>(2);
        let c = tables.push(&[9u32]);
        assert_eq!((a, b, c), (8, 12, 20));
        assert_eq!(&tables.words[..5], &[7; 5]);
        assert_eq!(tables.words[8..11], [1.0f32.to_bits(), 2.0f32.to_bits(), 3.0f32.to_bits()]);
        assert_eq!(&tables.words[12..20], &[0; 8]);
        assert_eq!(tables.words[20], 9);
    }
}
