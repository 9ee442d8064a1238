//! Fixed-capacity UTF-8 text for messages (reasons, fault descriptions, phase names).

use iceoryx2::prelude::ZeroCopySend;

/// UTF-8 text of at most `N` bytes stored inline, so it can live in shared memory.
/// Longer input is cut at a character boundary.
#[repr(C)]
#[derive(Clone, Copy, ZeroCopySend)]
#[type_name("walk.v8.FixedText")]
pub struct FixedText<const N: usize> {
    len: u32,
    bytes: [u8; N],
}

impl<const N: usize> FixedText<N> {
    /// The empty text.
    pub const EMPTY: Self = Self {
        len: 0,
        bytes: [0; N],
    };

    /// Copies `text`, cutting it at the last character boundary that fits.
    pub fn new(text: &str) -> Self {
        let mut out = Self::EMPTY;
        out.set(text);
        out
    }

    /// Replaces the content with `text` (cut to fit); no allocation.
    pub fn set(&mut self, text: &str) {
        let mut end = text.len().min(N);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        self.bytes[..end].copy_from_slice(&text.as_bytes()[..end]);
        self.len = end as u32;
    }

    /// The text; empty if the bytes received are not valid UTF-8.
    pub fn as_str(&self) -> &str {
        let len = (self.len as usize).min(N);
        core::str::from_utf8(&self.bytes[..len]).unwrap_or("")
    }

    /// True when no text is stored.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// Appends, cutting at the capacity (never fails, never allocates), so a message can be
/// composed with `write!` on the real-time path.
impl<const N: usize> core::fmt::Write for FixedText<N> {
    fn write_str(&mut self, text: &str) -> core::fmt::Result {
        let len = (self.len as usize).min(N);
        let mut end = text.len().min(N - len);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        self.bytes[len..len + end].copy_from_slice(&text.as_bytes()[..end]);
        self.len = (len + end) as u32;
        Ok(())
    }
}

impl<const N: usize> FixedText<N> {
    /// Empties the text.
    pub fn clear(&mut self) {
        self.len = 0;
    }
}

impl<const N: usize> Default for FixedText<N> {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl<const N: usize> core::fmt::Debug for FixedText<N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        core::fmt::Debug::fmt(self.as_str(), f)
    }
}

impl<const N: usize> core::fmt::Display for FixedText<N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuts_at_char_boundary() {
        let text = FixedText::<5>::new("abcdé"); // é is 2 bytes: only "abcd" fits
        assert_eq!(text.as_str(), "abcd");
        assert_eq!(FixedText::<8>::new("hold").as_str(), "hold");
        assert!(FixedText::<8>::EMPTY.is_empty());
    }

    #[test]
    fn write_appends_and_cuts_at_the_capacity() {
        use core::fmt::Write;
        let mut text = FixedText::<10>::new("ab");
        write!(text, "-{}-", 123).unwrap();
        assert_eq!(text.as_str(), "ab-123-");
        write!(text, "éééé").unwrap();
        assert_eq!(text.as_str(), "ab-123-é");
    }
}
