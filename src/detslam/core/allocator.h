// The C library's allocator, set for a loop that allocates and frees image-sized buffers over and
// over (pyramids, masks). With glibc's defaults, when the freed top of the heap outgrows the trim
// threshold (twice the largest block freed) it goes back to the kernel and the next round's
// buffers are faulted in again page by page, which costs more than the work done on them where
// page faults are slow (virtual machines). The kernel benchmarks call this: without it
// build/bench/detslam_bench_dynamic's BM_MaskCarry took 24 ms per frame, with it 3.7 ms, which is
// what carrying two people's masks costs inside `detslam run --realtime` (3.6-4.9 ms median per
// frame on walking_xyz tuning seeds 1-2). The detslam command itself does not call it: its
// threads reach that steady state with the defaults (sequential and camera-rate runs of the same
// sequence measured no faster with it).
#pragma once

namespace detslam {

// Blocks up to 32 MiB come from the heap, and up to 256 MiB of freed memory stays in the process
// instead of going back to the kernel. Call once at the start of main(), before other threads
// exist. Returns false where the C library offers no such settings (then nothing changes).
bool KeepFreedMemoryForReuse();

}  // namespace detslam
