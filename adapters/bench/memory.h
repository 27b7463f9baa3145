// Resident memory of this process, from /proc (Linux).
#pragma once

#include <cstddef>

namespace kmbvh {

size_t current_rss_bytes();
size_t peak_rss_bytes();  // high-water mark since start, or since reset_peak_rss()
// Returns freed heap memory to the system (malloc_trim), then resets the high-water mark
// to the current size (writes 5 to /proc/self/clear_refs), so that what a build then
// touches shows as growth even where it reuses freed blocks. False where the kernel does
// not allow the reset; the peak then covers the whole run.
bool start_peak_rss_measurement();

}  // namespace kmbvh
