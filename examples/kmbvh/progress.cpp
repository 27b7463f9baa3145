#include "progress.h"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
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

namespace {

std::string duration_text(double seconds) {
  const long s = long(seconds + 0.5);
  if (s < 60) return fmt::format("{}s", s);
  if (s < 3600) return fmt::format("{}m{:02}s", s / 60, s % 60);
  return fmt::format("{}h{:02}m", s / 3600, (s % 3600) / 60);
}

}  // namespace

void Progress::step(size_t done, size_t total, const std::string& message) {
  if (quiet_) return;
  constexpr size_t kWidth = 20;
  const size_t filled = total ? std::min(kWidth, done * kWidth / total) : kWidth;
  const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const std::string left = done > 0 && done < total ? ", ~" + duration_text(spent / double(done) * double(total - done)) + " left" : "";
  update(fmt::format("[{}{}] {}/{}  {}{}  {}", std::string(filled, '#'), std::string(kWidth - filled, '.'), done, total,
                     duration_text(spent), left, message));
}

void Progress::done() {
  if (open_) fmt::print(stderr, "\r\033[K");
  open_ = false;
}

}  // namespace kmbvh
