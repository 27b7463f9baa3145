// The instruction sets the wide traversal is compiled for, one of which is chosen when it
// first runs (Embree's ISA dispatch, in small): SSE4.2 (x86-64-v2, every x86-64 CPU of the
// last fifteen years), AVX2 (x86-64-v3) and AVX-512 (x86-64-v4). The best the CPU runs,
// unless the environment's KMBVH_ISA names another.
#pragma once

#include <string>
#include <vector>

namespace kmbvh {

enum class CpuIsa { Sse42, Avx2, Avx512 };

const char* to_string(CpuIsa isa);  // "sse4.2", "avx2", "avx512"

// Whether this CPU (and its operating system) runs code compiled for `isa`.
bool cpu_runs(CpuIsa isa);

// Every instruction set this CPU runs, lowest first.
std::vector<CpuIsa> cpu_isas();

// The instruction set for a request (KMBVH_ISA's value; null or empty: the best this CPU
// runs). Throws std::invalid_argument for a name that is none of them, and for one the
// CPU does not run, saying which it does.
CpuIsa choose_isa(const char* requested);

// choose_isa(getenv("KMBVH_ISA")), decided once per process.
CpuIsa traversal_isa();

}  // namespace kmbvh
