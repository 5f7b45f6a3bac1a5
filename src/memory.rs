//! Refusing work that would not fit in memory, before allocating.
//!
//! Rust aborts the process when an allocation fails, so a map too large for
//! the machine must be refused before it is allocated: the pipeline adds up
//! the bytes its maps will take and compares them with the memory the system
//! says is available (`MemAvailable` of /proc/meminfo), or with the cap set in
//! `SOFTSHADOW_MEMORY_LIMIT` (bytes), whichever is smaller. Where neither is
//! known nothing is refused beyond MAX_TEXELS per map.

use crate::error::{Error, Result};

/// The environment variable that caps the bytes one call may allocate (its
/// maps; an eye-view call's triangles, tree and images).
pub const LIMIT_VAR: &str = "SOFTSHADOW_MEMORY_LIMIT";

/// Requests below this many bytes fit on any machine this runs on: they
/// skip reading /proc/meminfo (tens of microseconds), which small maps
/// would notice.
const SURELY_FITS: u64 = 1 << 26;

fn cap() -> Option<u64> {
    std::env::var(LIMIT_VAR)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
}

/// Bytes available for maps: the smaller of the cap and MemAvailable.
pub fn available_bytes() -> Option<u64> {
    let cap = cap();
    let free = meminfo_bytes("MemAvailable:");
    match (cap, free) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The machine's memory (`MemTotal` of /proc/meminfo), where it is known.
pub fn total_bytes() -> Option<u64> {
    meminfo_bytes("MemTotal:")
}

/// A /proc/meminfo field (`field` with its colon), in bytes.
fn meminfo_bytes(field: &str) -> Option<u64> {
    std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find(|l| l.starts_with(field))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|kb| kb.parse::<u64>().ok())
            .map(|kb| kb.saturating_mul(1024))
    })
}

/// Bytes of `maps` f32 maps of `texels` texels each.
pub fn map_bytes(texels: usize, maps: usize) -> u64 {
    (texels as u64)
        .saturating_mul(maps as u64)
        .saturating_mul(4)
}

/// Refuses (TooLarge, naming `arg`) work needing `bytes` when fewer are available.
pub fn check_fits(arg: &str, what: &str, bytes: u64) -> Result<()> {
    let avail = if bytes < SURELY_FITS {
        cap()
    } else {
        available_bytes()
    };
    match avail {
        Some(avail) if bytes > avail => Err(Error::too_large(
            arg,
            format!(
                "{what} would need about {bytes} bytes of memory, more than the {avail} bytes \
                 available (MemAvailable, or {LIMIT_VAR})"
            ),
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_add_up_without_overflow() {
        assert_eq!(map_bytes(256 * 256, 4), 1 << 20);
        assert_eq!(map_bytes(usize::MAX, 8), u64::MAX);
        // Whatever the machine has, u64::MAX bytes do not fit when anything
        // is known about it.
        if available_bytes().is_some() {
            assert!(check_fits("resolution", "this", u64::MAX).is_err());
        }
        assert!(check_fits("resolution", "this", 0).is_ok());
    }
}
