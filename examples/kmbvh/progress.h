// Progress lines on stderr for long runs: rewritten in place on a terminal, one line each
// otherwise (logs, CI). Silent when quiet.
#pragma once

#include <string>

namespace kmbvh {

class Progress {
 public:
  explicit Progress(bool quiet);
  ~Progress();
  void update(const std::string& message);
  void done();  // ends the in-place line

 private:
  bool quiet_;
  bool terminal_;
  bool open_ = false;
};

}  // namespace kmbvh
