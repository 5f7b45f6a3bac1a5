//! An allocator that keeps freed large blocks for the next call instead of
//! giving their pages back to the kernel.
//!
//! Why. One eye-view render at 640×480 allocates and frees about 30 MB of
//! buffers (the G-buffer, the visible points, the maps, the images handed to
//! numpy). glibc serves blocks that large with mmap and returns them with
//! munmap (or trims them off its heaps), so the next call touches fresh
//! pages, and the kernel faults and zeroes every one of them: on the city
//! scene, 5 400 page faults and 15 ms of system time a render, which took
//! 32 ms, 18 ms with the blocks kept (`benchmarks/bench_alloc.py`,
//! docs/benchmarks/alloc.md). The Python extension
//! installs `BlockCache` as its global allocator (src/python/mod.rs); the
//! core is allocator-agnostic.
//!
//! How. A request of at least MIN_CACHED bytes (alignment at most
//! MAX_ALIGN) is rounded up to a size class (CLASSES_PER_OCTAVE per power of
//! two, so at most 1/8 is wasted) and taken from the cache when a block of
//! that class is there, else from the system allocator. A freed block of a
//! class goes into the cache, which evicts its idle blocks round robin to
//! hold at most SLOTS blocks and its limit in bytes in all: a sixteenth of
//! the machine's memory, within [MIN_LIMIT, MAX_LIMIT]. (A fixed 256 MB
//! was too small for a 2 000 000-triangle scene, whose call frees more than
//! that: its BVH refit took 98 ms with it, 32 ms with 1 GiB, on 2 cores.) Every block of a
//! cached layout is allocated at its class size, so a block's size is
//! always known from its layout. Smaller requests go straight to the system.
//! `SOFTSHADOW_BLOCK_CACHE`, read when the extension is imported, turns the
//! cache `off` (`benchmarks/bench_alloc.py` measures both) or sets its limit
//! in bytes.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Requests smaller than this go straight to the system allocator.
pub const MIN_CACHED: usize = 1 << 17;
/// Largest alignment the cache serves (what Vec of any core type needs).
pub const MAX_ALIGN: usize = 64;
/// The least and the most bytes the cache's default limit keeps idle.
pub const MIN_LIMIT: usize = 256 << 20;
pub const MAX_LIMIT: usize = 1 << 30;
/// The most blocks idle in the cache.
pub const SLOTS: usize = 128;
const CLASSES_PER_OCTAVE: u32 = 8;

/// The size a cached request of `size` bytes is allocated at: `size`
/// rounded up to a multiple of 2^(floor(log2 size) - 3).
pub fn class_size(size: usize) -> usize {
    let octave = usize::BITS - 1 - size.leading_zeros();
    let step = 1usize << octave.saturating_sub(CLASSES_PER_OCTAVE.trailing_zeros());
    size.div_ceil(step).saturating_mul(step)
}

#[derive(Clone, Copy)]
struct Slot {
    /// The block's address (0: empty), class size and alignment.
    addr: usize,
    size: usize,
    align: usize,
}

const EMPTY: Slot = Slot {
    addr: 0,
    size: 0,
    align: 0,
};

struct Cache {
    slots: [Slot; SLOTS],
    bytes: usize,
    /// The slot evicted next when a freed block needs room (round robin).
    next_evict: usize,
}

/// The system allocator with a bounded cache of freed large blocks.
pub struct BlockCache {
    cache: Mutex<Cache>,
    enabled: AtomicBool,
    /// The most bytes idle in the cache.
    limit: AtomicUsize,
}

/// The environment variable that turns the cache off (`off`) or sets its
/// limit (a count of bytes).
pub const TOGGLE_VAR: &str = "SOFTSHADOW_BLOCK_CACHE";

impl Default for BlockCache {
    fn default() -> Self {
        Self::new()
    }
}

impl BlockCache {
    pub const fn new() -> BlockCache {
        BlockCache {
            cache: Mutex::new(Cache {
                slots: [EMPTY; SLOTS],
                bytes: 0,
                next_evict: 0,
            }),
            enabled: AtomicBool::new(true),
            limit: AtomicUsize::new(MIN_LIMIT),
        }
    }

    /// Turns the cache on or off; off gives every idle block back.
    pub fn set_enabled(&self, on: bool) {
        self.enabled.store(on, Ordering::Relaxed);
        if !on {
            let mut c = self.cache.lock().unwrap_or_else(|e| e.into_inner());
            c.release();
        }
    }

    /// Reads TOGGLE_VAR and the machine's memory (call it outside any
    /// allocation: it allocates).
    pub fn configure_from_env(&self) {
        let var = std::env::var(TOGGLE_VAR).unwrap_or_default();
        let var = var.trim();
        let limit = var.parse::<usize>().ok().unwrap_or_else(|| {
            let sixteenth = crate::memory::total_bytes().map_or(0, |b| (b / 16) as usize);
            sixteenth.clamp(MIN_LIMIT, MAX_LIMIT)
        });
        self.set_limit(limit);
        self.set_enabled(!var.eq_ignore_ascii_case("off"));
    }

    /// The most bytes idle in the cache from now on (idle blocks over it
    /// are given back).
    pub fn set_limit(&self, bytes: usize) {
        self.limit.store(bytes, Ordering::Relaxed);
        let mut c = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        if c.bytes > bytes {
            c.release();
        }
    }

    #[inline]
    fn limit(&self) -> usize {
        self.limit.load(Ordering::Relaxed)
    }

    /// Whether blocks of `layout` go through the cache.
    #[inline]
    fn cached(layout: Layout) -> bool {
        layout.size() >= MIN_CACHED && layout.align() <= MAX_ALIGN
    }

    #[inline]
    fn is_enabled(&self) -> bool {
        self.enabled.load(Ordering::Relaxed)
    }

    /// The layout a cached `layout` is allocated at.
    #[inline]
    fn class_layout(layout: Layout) -> Layout {
        // Only a request within an eighth of isize::MAX has no class that
        // fits; it keeps its own layout (alloc and dealloc both come here,
        // so they agree).
        Layout::from_size_align(class_size(layout.size()), layout.align()).unwrap_or(layout)
    }

    /// An idle block of exactly the layout `class`, if there is one.
    fn take(&self, class: Layout) -> Option<*mut u8> {
        if !self.is_enabled() {
            return None;
        }
        let mut c = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        let k = c
            .slots
            .iter()
            .position(|s| s.addr != 0 && s.size == class.size() && s.align == class.align())?;
        let addr = c.slots[k].addr;
        c.slots[k] = EMPTY;
        c.bytes -= class.size();
        Some(addr as *mut u8)
    }

    /// Keeps the block `ptr` of layout `class`, evicting idle blocks (round
    /// robin, so that blocks of sizes no longer asked for do not stay) until
    /// it fits; false for a block larger than the whole cache.
    fn keep(&self, ptr: *mut u8, class: Layout) -> bool {
        let size = class.size();
        let limit = self.limit();
        if !self.is_enabled() || size > limit {
            return false;
        }
        let mut c = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        let mut free = c.slots.iter().position(|s| s.addr == 0);
        while free.is_none() || c.bytes + size > limit {
            let k = c.next_evict;
            c.next_evict = (k + 1) % SLOTS;
            let s = c.slots[k];
            if s.addr != 0 {
                if let Ok(l) = Layout::from_size_align(s.size, s.align) {
                    // SAFETY: the block was allocated by System at this layout.
                    unsafe { System.dealloc(s.addr as *mut u8, l) };
                }
                c.slots[k] = EMPTY;
                c.bytes -= s.size;
                free = Some(k);
            }
        }
        let k = free.unwrap_or(0);
        c.slots[k] = Slot {
            addr: ptr as usize,
            size,
            align: class.align(),
        };
        c.bytes += size;
        true
    }

    /// Bytes idle in the cache.
    pub fn idle_bytes(&self) -> usize {
        self.cache.lock().unwrap_or_else(|e| e.into_inner()).bytes
    }
}

impl Cache {
    /// Gives every idle block back to the system.
    fn release(&mut self) {
        for s in self.slots.iter_mut().filter(|s| s.addr != 0) {
            if let Ok(l) = Layout::from_size_align(s.size, s.align) {
                // SAFETY: the block was allocated by System at this layout.
                unsafe { System.dealloc(s.addr as *mut u8, l) };
            }
            *s = EMPTY;
        }
        self.bytes = 0;
    }
}

impl Drop for BlockCache {
    /// Gives the idle blocks back (a global allocator is never dropped; a
    /// local one, as in the tests, is).
    fn drop(&mut self) {
        self.cache
            .get_mut()
            .unwrap_or_else(|e| e.into_inner())
            .release();
    }
}

// SAFETY: every block handed out is either the system allocator's own, or a
// block the system allocated at `class_layout(layout)` and that this cache
// took back whole; a cached layout is always allocated and freed at its
// class layout, so the system sees matching layouts.
unsafe impl GlobalAlloc for BlockCache {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !Self::cached(layout) {
            return unsafe { System.alloc(layout) };
        }
        let class = Self::class_layout(layout);
        match self.take(class) {
            Some(p) => p,
            None => unsafe { System.alloc(class) },
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if !Self::cached(layout) {
            return unsafe { System.alloc_zeroed(layout) };
        }
        let class = Self::class_layout(layout);
        match self.take(class) {
            Some(p) => {
                unsafe { p.write_bytes(0, layout.size()) };
                p
            }
            None => unsafe { System.alloc_zeroed(class) },
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if !Self::cached(layout) {
            return unsafe { System.dealloc(ptr, layout) };
        }
        let class = Self::class_layout(layout);
        if !self.keep(ptr, class) {
            unsafe { System.dealloc(ptr, class) };
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let Ok(new) = Layout::from_size_align(new_size, layout.align()) else {
            return std::ptr::null_mut();
        };
        match (Self::cached(layout), Self::cached(new)) {
            (false, false) => unsafe { System.realloc(ptr, layout, new_size) },
            (true, true) if class_size(layout.size()) == class_size(new_size) => ptr,
            _ => {
                let p = unsafe { self.alloc(new) };
                if !p.is_null() {
                    unsafe {
                        std::ptr::copy_nonoverlapping(ptr, p, layout.size().min(new_size));
                        self.dealloc(ptr, layout);
                    }
                }
                p
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_round_up_by_at_most_an_eighth() {
        for size in [
            MIN_CACHED,
            MIN_CACHED + 1,
            1 << 20,
            3 << 20,
            7_372_800,
            1 << 30,
        ] {
            let c = class_size(size);
            assert!(c >= size && (c - size) * 8 <= size, "{size} -> {c}");
            assert_eq!(class_size(c), c, "a class is its own class");
        }
        assert_eq!(class_size(1 << 20), 1 << 20);
        assert_eq!(class_size((1 << 20) + 1), (1 << 20) + (1 << 17));
    }

    #[test]
    fn a_freed_block_is_reused_and_the_cache_is_bounded() {
        let a = BlockCache::new();
        let layout = Layout::from_size_align(3 << 20, 8).unwrap();
        unsafe {
            let p = a.alloc(layout);
            assert!(!p.is_null());
            p.write_bytes(7, layout.size());
            a.dealloc(p, layout);
            assert_eq!(a.idle_bytes(), class_size(layout.size()));
            // The same class comes back, zeroed when asked.
            let q = a.alloc_zeroed(Layout::from_size_align((3 << 20) - 5, 8).unwrap());
            assert_eq!(q, p);
            assert_eq!(a.idle_bytes(), 0);
            assert!(std::slice::from_raw_parts(q, (3 << 20) - 5)
                .iter()
                .all(|&b| b == 0));
            // Growing within the class keeps the block; past it moves it.
            let r = a.realloc(
                q,
                Layout::from_size_align((3 << 20) - 5, 8).unwrap(),
                3 << 20,
            );
            assert_eq!(r, q);
            r.write_bytes(9, 16);
            let s = a.realloc(r, layout, 8 << 20);
            assert!(std::slice::from_raw_parts(s, 16).iter().all(|&b| b == 9));
            assert_eq!(a.idle_bytes(), class_size(layout.size()));
            // Shrinking below MIN_CACHED hands it to the system.
            let t = a.realloc(s, Layout::from_size_align(8 << 20, 8).unwrap(), 100);
            assert!(std::slice::from_raw_parts(t, 16).iter().all(|&b| b == 9));
            a.dealloc(t, Layout::from_size_align(100, 8).unwrap());
            // Never more than the limit idle: the older block goes.
            let big = Layout::from_size_align(MIN_LIMIT / 2 + 1, 8).unwrap();
            let (x, y) = (a.alloc(big), a.alloc(big));
            a.dealloc(x, big);
            a.dealloc(y, big);
            assert!(a.idle_bytes() <= MIN_LIMIT);
            assert_eq!(a.take(BlockCache::class_layout(big)), Some(y));
            // Never more than SLOTS blocks idle.
            let small = Layout::from_size_align(MIN_CACHED, 8).unwrap();
            const { assert!((SLOTS + 3) * MIN_CACHED < MIN_LIMIT) };
            let blocks: Vec<*mut u8> = (0..SLOTS + 3).map(|_| a.alloc(small)).collect();
            for &p in &blocks {
                a.dealloc(p, small);
            }
            let idle = a
                .cache
                .lock()
                .unwrap()
                .slots
                .iter()
                .filter(|s| s.addr != 0)
                .count();
            assert_eq!(idle, SLOTS);
        }
    }

    #[test]
    fn turned_off_it_keeps_nothing() {
        let a = BlockCache::new();
        let layout = Layout::from_size_align(2 << 20, 8).unwrap();
        unsafe {
            a.dealloc(a.alloc(layout), layout);
            assert!(a.idle_bytes() > 0);
            a.set_enabled(false);
            assert_eq!(a.idle_bytes(), 0);
            a.dealloc(a.alloc(layout), layout);
            assert_eq!(a.idle_bytes(), 0);
        }
    }

    #[test]
    fn the_limit_bounds_what_stays_idle() {
        let a = BlockCache::new();
        let layout = Layout::from_size_align(2 << 20, 8).unwrap();
        unsafe {
            a.set_limit(8 << 20);
            let blocks: Vec<*mut u8> = (0..6).map(|_| a.alloc(layout)).collect();
            for &p in &blocks {
                a.dealloc(p, layout);
            }
            assert_eq!(a.idle_bytes(), 4 * class_size(2 << 20));
            // A lower limit gives the idle blocks back; a block over it is
            // never kept.
            a.set_limit(1 << 20);
            assert_eq!(a.idle_bytes(), 0);
            a.dealloc(a.alloc(layout), layout);
            assert_eq!(a.idle_bytes(), 0);
        }
    }

    #[test]
    fn small_and_overaligned_requests_bypass_the_cache() {
        let a = BlockCache::new();
        unsafe {
            let small = Layout::from_size_align(4096, 8).unwrap();
            let p = a.alloc(small);
            a.dealloc(p, small);
            let odd = Layout::from_size_align(2 << 20, 4096).unwrap();
            let q = a.alloc(odd);
            assert_eq!(q as usize % 4096, 0);
            a.dealloc(q, odd);
        }
        assert_eq!(a.idle_bytes(), 0);
    }
}
