//! Recording ids that depend only on their inputs.

/// A recording id that depends only on `parts` (for example the trace's
/// bytes and the options), so replaying the same trace twice gives the same
/// recording id.
pub fn recording_id(parts: &[&[u8]]) -> String {
    let mut h = IdHasher::new();
    for part in parts {
        h.update(&(part.len() as u64).to_le_bytes());
        h.update(part);
    }
    h.finish()
}

/// Streaming hash for [`recording_id`]s: FNV-1a with 128 bits, printed as
/// `sweeptrace-<32 hex digits>`. Not cryptographic; stable across builds.
#[derive(Clone, Copy, Debug)]
pub struct IdHasher(u128);

impl Default for IdHasher {
    fn default() -> Self {
        IdHasher::new()
    }
}

impl IdHasher {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;

    /// An empty hash.
    pub fn new() -> IdHasher {
        IdHasher(Self::OFFSET)
    }

    /// Adds bytes.
    pub fn update(&mut self, bytes: &[u8]) {
        let mut h = self.0;
        for &b in bytes {
            h ^= b as u128;
            h = h.wrapping_mul(Self::PRIME);
        }
        self.0 = h;
    }

    /// The hash as a number.
    pub(crate) fn value(&self) -> u128 {
        self.0
    }

    /// The recording id.
    pub fn finish(&self) -> String {
        format!("sweeptrace-{:032x}", self.0)
    }
}
