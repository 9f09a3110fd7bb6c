#include "renderer/core/files/file_dependencies.h"

namespace ofl {
namespace {
thread_local FileDependencyRecorder* active = nullptr;
}

FileDependencyRecorder::FileDependencyRecorder() : previous_(active) { active = this; }

FileDependencyRecorder::~FileDependencyRecorder() { active = previous_; }

bool recording_file_dependencies() { return active != nullptr; }

void note_file_dependency(const std::filesystem::path& file) {
  if (!active) return;
  std::error_code ec;
  std::filesystem::path p = std::filesystem::absolute(file, ec);
  if (ec) p = file;
  p = p.lexically_normal();
  if (!std::filesystem::is_regular_file(p, ec)) return;
  for (FileDependencyRecorder* r = active; r; r = r->previous_) r->files_.insert(p);
}

}  // namespace ofl
