#include "threads.h"

#include <omp.h>

namespace kmbvh {
namespace {
int g_threads = 0;
}

void set_thread_count(int n) {
  g_threads = n > 0 ? n : omp_get_num_procs();
  omp_set_num_threads(g_threads);
}

int thread_count() { return g_threads > 0 ? g_threads : omp_get_max_threads(); }

}  // namespace kmbvh
