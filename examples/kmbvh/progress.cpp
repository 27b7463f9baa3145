#include "progress.h"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>

namespace kmbvh {

Progress::Progress(bool quiet) : quiet_(quiet), terminal_(isatty(fileno(stderr)) != 0) {}
Progress::~Progress() { done(); }

void Progress::update(const std::string& message) {
  if (quiet_) return;
  if (terminal_) {
    fmt::print(stderr, "\r\033[K{}", message);
    open_ = true;
  } else {
    fmt::print(stderr, "{}\n", message);
  }
  std::fflush(stderr);
}

void Progress::done() {
  if (open_) fmt::print(stderr, "\r\033[K");
  open_ = false;
}

}  // namespace kmbvh
