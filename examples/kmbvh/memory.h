// Resident memory of this process, from /proc (Linux).
#pragma once

#include <cstddef>

namespace kmbvh {

size_t current_rss_bytes();
size_t peak_rss_bytes();  // high-water mark since start, or since reset_peak_rss()
// Resets the high-water mark to the current size (writes 5 to /proc/self/clear_refs).
// False where the kernel does not allow it; the peak then covers the whole run.
bool reset_peak_rss();

}  // namespace kmbvh
