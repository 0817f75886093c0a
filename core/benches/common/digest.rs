//! The digest the timing reports print for a grown tree or garden: FNV-1a (64 bit) of its saved
//! JSON, as hex. The README's digests are these.

pub fn fnv1a_hex(bytes: &[u8]) -> String {
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    format!("{hash:016x}")
}
