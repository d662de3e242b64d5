//! The global allocator in wasm: the standard one (dlmalloc), with the memory grown in steps
//! of at least [`MIN_STEP_BYTES`] instead of one 64 KiB page at a time.
//!
//! dlmalloc asks the engine for what an allocation lacks whenever its free memory runs out,
//! rounded up to one 64 KiB page, and each `memory.grow` costs a fixed 0.2–0.6 ms in V8 (3 000
//! one-page grows from JavaScript: 0.64 s): the first load of OpenSubdiv's car cage, which
//! grows the memory to 186 MB, took 2.0–3.3 s in Node, against 0.75 s once the memory was
//! there. Here, after an allocation that grew the memory, a block
//! of one step is allocated and freed at once: dlmalloc grows the memory by the step in one
//! call and keeps the block as free memory for what comes next. The step is a share of the
//! memory already there (1/32), so growing from `M0` to `M` bytes takes about
//! `32 ln(M / M0)` calls (about 120 from 4 to 186 MB), and at most one step is left
//! unused. Natively the standard allocator is used as it is.

use std::alloc::{GlobalAlloc, Layout};
use std::arch::wasm32::memory_size;

/// Least memory grown at once (bytes): 16 pages.
const MIN_STEP_BYTES: usize = 1 << 20;
/// The step as a share of the memory there already: 1/32, so at most about 3 % of the
/// memory is left unused after the last step.
const STEP_SHARE_LOG2: u32 = 5;
/// Bytes per wasm page.
const PAGE_BYTES: usize = 1 << 16;

/// dlmalloc (`System`), growing the memory in steps.
pub struct GrowInSteps;

#[global_allocator]
static ALLOCATOR: GrowInSteps = GrowInSteps;

impl GrowInSteps {
    /// After an allocation that grew the memory from `pages_before` pages: one step more,
    /// taken from the engine in one `memory.grow` and handed back to dlmalloc's free memory.
    fn step_if_grown(pages_before: usize) {
        let pages = memory_size::<0>();
        if pages == pages_before {
            return;
        }
        let step = ((pages * PAGE_BYTES) >> STEP_SHARE_LOG2).max(MIN_STEP_BYTES);
        let Ok(layout) = Layout::from_size_align(step, 16) else {
            return;
        };
        // SAFETY: `layout` has a non-zero size; the block is freed with the layout it was
        // allocated with, and nothing else sees it. Where the engine refuses the memory the
        // allocation is null and nothing is freed (the next allocation asks for what it needs).
        unsafe {
            let block = system::alloc(layout);
            if !block.is_null() {
                system::dealloc(block, layout);
            }
        }
    }
}

/// `System`'s calls, each compiled once: inlined into each caller here, dlmalloc's code was
/// copied four times (the planner's module 612 -> 635 KB gzipped). The allocator's own calls
/// are not inlined either, or every allocation in the crate grows by the memory test.
mod system {
    use std::alloc::{GlobalAlloc, Layout, System};

    #[inline(never)]
    pub unsafe fn alloc(layout: Layout) -> *mut u8 {
        System.alloc(layout)
    }

    #[inline(never)]
    pub unsafe fn alloc_zeroed(layout: Layout) -> *mut u8 {
        System.alloc_zeroed(layout)
    }

    #[inline(never)]
    pub unsafe fn dealloc(ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }

    #[inline(never)]
    pub unsafe fn realloc(ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        System.realloc(ptr, layout, new_size)
    }
}

// SAFETY: every call is passed to `System` unchanged, with the caller's pointer and layout;
// `step_if_grown` only allocates and frees a block of its own.
unsafe impl GlobalAlloc for GrowInSteps {
    #[inline(never)]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let before = memory_size::<0>();
        let p = system::alloc(layout);
        Self::step_if_grown(before);
        p
    }

    #[inline(never)]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let before = memory_size::<0>();
        let p = system::alloc_zeroed(layout);
        Self::step_if_grown(before);
        p
    }

    #[inline(never)]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        system::dealloc(ptr, layout)
    }

    #[inline(never)]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let before = memory_size::<0>();
        let p = system::realloc(ptr, layout, new_size);
        Self::step_if_grown(before);
        p
    }
}
