// Process-wide allocator settings for calibench's executables.
#pragma once

namespace calibench {

// Keeps freed memory in the process for reuse instead of handing it back to the kernel at once.
// glibc maps each block above 128 kB-32 MB (images, clouds, depth grids, summed-area tables)
// with mmap and unmaps it on free, so each pair's buffers fault in fresh, zeroed pages again;
// on the 2-core reference VM those page faults were a third of the 40-pair calibration's time
// and most of the LRF depth features' (37 ms of back-projection for 230k points). Peak memory
// is unchanged: the high-water mark is what it was; only what is between pairs stays mapped, so
// the resident size stays at the peak until ReleaseFreedMemory.
// Call once at the start of main(). No effect (and no failure) with another C library.
void KeepFreedMemoryForReuse();
// Hands the free memory kept so far back to the kernel: the workbench calls it once its pairs
// have loaded, since it then stays open with what it holds (40 OS0-128 pairs: 210 MiB resident
// instead of 242; loading them without keeping freed memory took 9.0 s instead of 3.9 s).
void ReleaseFreedMemory();

}  // namespace calibench
