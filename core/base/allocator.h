// Process-wide allocator settings for calibench's executables.
#pragma once

namespace calibench {

// Keeps freed memory in the process for reuse instead of handing it back to the kernel at once.
// glibc maps each block above 128 kB-32 MB (images, clouds, depth grids, summed-area tables)
// with mmap and unmaps it on free, so each pair's buffers fault in fresh, zeroed pages again;
// on the 2-core reference VM those page faults were a third of the 40-pair calibration's time
// and most of the LRF depth features' (37 ms of back-projection for 230k points). Peak memory
// is unchanged: the high-water mark is what it was; only what is between pairs stays mapped.
// Call once at the start of main(). No effect (and no failure) with another C library.
void KeepFreedMemoryForReuse();

}  // namespace calibench
