//! The process memory policy of rendering many scenes (glibc on Linux; nothing
//! elsewhere), set once before the first render by `rh-pipeline build` and by the render
//! bench, so that both measure the same process. Measurements: docs/benchmarks.md,
//! "Render memory".

/// Sets the policy; call before the rendering threads start (the arena limit applies to
/// threads that have not allocated yet).
pub fn set_render_policy() {
    no_huge_pages();
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets allocator parameters; all three are valid for glibc.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD);
        libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD);
        libc::mallopt(libc::M_ARENA_MAX, 1);
    }
}

/// Allocations from this size up always come from the system (mmap) and go back to it
/// when freed: a 720p frame (3.7 MB), its RGB copy for a PNG (2.8 MB), libx264's frame
/// buffers, lavapipe's memory blocks (4 MB and up). glibc otherwise raises its mmap
/// threshold to the largest block freed so far (up to 32 MB), after which such buffers
/// are carved from the malloc arenas, whose freed space fragments and stays resident:
/// peak RSS crept up scene by scene. Not lower: lavapipe allocates and frees about
/// 1.2 MB per frame, which mapped each time cost 5x the system time.
const MMAP_THRESHOLD: i32 = 2 << 20;

/// Free memory at the top of the heap that stays with the process (fixing the mmap
/// threshold also fixes this at its 128 KiB default, which returned lavapipe's
/// per-frame memory to the system and faulted it in again on the next frame: about 3%
/// of a build's CPU time, all of it system time). Affordable with one arena: with one
/// per thread (workers, encoders, lavapipe's threads) each could keep it, and a 64 MiB
/// threshold raised `build --n 64`'s peak RSS from 414 to 648 MB.
const TRIM_THRESHOLD: i32 = 32 << 20;

/// libx264 asks for transparent huge pages for its frame buffers
/// (`madvise(MADV_HUGEPAGE)`), which makes every 2 MB region it touches at all resident:
/// off for this process.
fn no_huge_pages() {
    #[cfg(target_os = "linux")]
    // SAFETY: prctl with integer arguments only; a failure leaves the default.
    unsafe {
        libc::prctl(libc::PR_SET_THP_DISABLE, 1, 0, 0, 0);
    }
}

/// Returns the free pages of the malloc arena to the system (after each scene: its
/// encoders' and frames' buffers).
pub fn release_free_pages() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only walks the allocator's own free lists.
    unsafe {
        libc::malloc_trim(0);
    }
}
