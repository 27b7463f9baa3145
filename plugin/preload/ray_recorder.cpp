#include "ray_recorder.h"

#include <fmt/format.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <vector>

#include "adapters/rays/ray_file.h"
#include "plugin/plugin_config.h"

namespace kmbvh::plugin {
namespace {

class Recorder {
 public:
  Recorder()
      : path_(plugin_config().record_rays), limit_(plugin_config().record_limit), every_(plugin_config().record_every) {}

  // The file, at exit: written whole, so a crash leaves no half file behind. Queries that
  // come later (threads still running) are not recorded.
  void write() {
    if (path_.empty()) return;
    full_.store(true);
    std::lock_guard<std::mutex> lock(mutex_);
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    bool ok = f && std::fwrite(kAppRaysMagic, sizeof(kAppRaysMagic), 1, f) == 1 &&
              std::fwrite(rays_.data(), sizeof(AppRayRecord), rays_.size(), f) == rays_.size();
    if (f) ok = std::fclose(f) == 0 && ok;
    log_line(ok ? fmt::format("{} queries recorded to {}", rays_.size(), path_)
                : fmt::format("the recorded queries could not be written to {}", path_));
  }

  bool on() const { return !path_.empty(); }

  void record(const void* scene, const Ray& ray, Query query) {
    if (full_.load(std::memory_order_relaxed)) return;
    const void* none = nullptr;
    if (scene_.compare_exchange_strong(none, scene))
      log_line(fmt::format("recording the queries on the first scene queried to {}", path_));
    else if (none != scene)
      return;  // another scene's
    std::lock_guard<std::mutex> lock(mutex_);
    if (rays_.size() >= limit_) return full_.store(true, std::memory_order_relaxed);
    if (seen_++ % every_ != 0) return;
    rays_.push_back(AppRayRecord{{ray.org.x, ray.org.y, ray.org.z},
                                 {ray.dir.x, ray.dir.y, ray.dir.z},
                                 ray.tnear,
                                 ray.tfar,
                                 query == Query::Any ? 1u : 0u});
  }

 private:
  const std::string path_;
  const size_t limit_;
  const uint64_t every_;
  uint64_t seen_ = 0;  // the scene's queries so far, under the mutex
  std::atomic<const void*> scene_{nullptr};
  std::atomic<bool> full_{false};
  std::mutex mutex_;
  std::vector<AppRayRecord> rays_;
};

// Never destroyed: application threads may still query while the process exits.
Recorder& recorder() {
  static Recorder* const r = [] {
    Recorder* made = new Recorder;
    if (made->on()) std::atexit([] { recorder().write(); });
    return made;
  }();
  return *r;
}

}  // namespace

bool recording_rays() {
  static const bool on = recorder().on();
  return on;
}

void record_ray(const void* scene, const Ray& ray, Query query) {
  try {
    recorder().record(scene, ray, query);
  } catch (const std::bad_alloc&) {  // the application goes on; the file holds what fitted
  }
}

}  // namespace kmbvh::plugin
