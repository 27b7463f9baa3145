// Progress lines on stderr for long runs: rewritten in place on a terminal, one line each
// otherwise (logs, CI). Silent when quiet. For runs of many steps, a bar with the time
// spent and an estimate of the time left.
#pragma once

#include <chrono>
#include <string>

namespace kmbvh {

class Progress {
 public:
  explicit Progress(bool quiet);
  ~Progress();
  void update(const std::string& message);
  // "[#######.............] 7/20  3m05s, ~5m40s left  message": `done` of `total` steps
  // finished; the estimate assumes the steps left take as long as those done.
  void step(size_t done, size_t total, const std::string& message);
  void done();  // ends the in-place line

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  bool quiet_;
  bool terminal_;
  bool open_ = false;
};

}  // namespace kmbvh
