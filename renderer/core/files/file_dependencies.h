// Which files a piece of work read: while a FileDependencyRecorder lives on a thread, every file
// named through a JSON document (JsonNode::existing_file, JsonFile::load: meshes, spectra, EEMs,
// textures, presets, fluorophore sidecars) and the other inputs that readers note themselves
// (glTF buffers, the hemoglobin tables) are collected. The sweep's render cache hashes their bytes
// into its key, so a changed spectrum CSV means a new render. Recording is per thread and costs
// nothing when no recorder is active.
#pragma once
#include <filesystem>
#include <set>
#include <string>

namespace ofl {

class FileDependencyRecorder {
 public:
  FileDependencyRecorder();   // becomes the thread's active recorder (recorders nest)
  ~FileDependencyRecorder();  // the previous one is active again
  FileDependencyRecorder(const FileDependencyRecorder&) = delete;
  FileDependencyRecorder& operator=(const FileDependencyRecorder&) = delete;
  // Absolute, lexically normal paths of every regular file noted while this recorder was active.
  const std::set<std::filesystem::path>& files() const { return files_; }

 private:
  friend void note_file_dependency(const std::filesystem::path& file);
// Whether a recorder is active on this thread (a cheap test for callers in inner loops).
bool recording_file_dependencies();
  std::set<std::filesystem::path> files_;
  FileDependencyRecorder* previous_;
};

// Adds `file` to the thread's active recorder (and to every recorder it is nested in); does
// nothing without one.
void note_file_dependency(const std::filesystem::path& file);
// Whether a recorder is active on this thread (a cheap test for callers in inner loops).
bool recording_file_dependencies();

}  // namespace ofl
