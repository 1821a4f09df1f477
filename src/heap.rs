//! FFI to the C allocator: after a phase that freed much memory, its free pages go back to the
//! operating system. glibc keeps freed heap pages resident for reuse, so the next phase's
//! allocations, placed elsewhere, add to the resident set; the peak RSS a cluster job is
//! charged for then counts memory no phase holds at once.

/// Returns the heap's free pages to the operating system (glibc `malloc_trim(0)`, which also
/// releases whole free pages inside the heap). Rank-local; a no-op elsewhere than glibc.
pub fn release_free_pages() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only walks the allocator's own free lists.
    unsafe {
        libc::malloc_trim(0);
    }
}
