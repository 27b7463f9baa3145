// The number of CPU threads kmbvh's CPU backend (OpenMP) and Embree's device use; one
// setting for the whole process, as rtcNewDevice("threads=N") is for Embree.
#pragma once

namespace kmbvh {

// n = 0 means every hardware thread.
void set_thread_count(int n);
int thread_count();

}  // namespace kmbvh
