// Every file the tools write goes through here: the bytes go to a temporary beside the final name
// (".<name>.<host>.<pid>.tmp", same folder, so the rename cannot cross file systems), every write,
// the fsync and the close are checked, and only then is the temporary renamed over the final name.
// Any failure (full disk, no permission, a file where the folder should be) removes the temporary
// and throws an InputError naming the final file, so a command never exits 0 with a file missing
// or cut short, and never leaves temporaries behind.
#pragma once
#include <filesystem>
#include <functional>
#include <string>

namespace ofl {

// Writes `contents` to `file` atomically (temporary + fsync + rename + fsync of the folder).
void write_file_atomic(const std::filesystem::path& file, const std::string& contents);

// This machine's name as it appears in temporary names ('.' and '/' replaced by '_').
std::string host_tag();

// The temporary name used for `file` by this process.
std::filesystem::path temporary_for(const std::filesystem::path& file);

// For libraries that insist on writing a file by name themselves (libmatio): `write(temp)` writes
// the temporary and must throw on any error it sees; then the temporary is fsynced (an error there
// counts too) and renamed over `file`. On any failure the temporary is removed and an InputError
// naming `file` is thrown. A device or pipe (`-o /dev/null`) gets the bytes of a temporary
// written in the system's temporary folder, since the library may seek or read back its file.
void write_via_temporary(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write);

}  // namespace ofl
