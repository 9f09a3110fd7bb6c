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
void write_bytes_atomic(const std::filesystem::path& file, const char* data, size_t size);

// This machine's name as it appears in temporary names ('.' and '/' replaced by '_').
std::string host_tag();

// The temporary name used for `file` by this process.
std::filesystem::path temporary_for(const std::filesystem::path& file);

// For libraries that insist on writing a file by name themselves (libmatio, an OpenImageIO writer
// without an in-memory mode): `write(name)` writes to `name`, an in-memory file (a memfd, named
// /proc/self/fd/N; a private file in the system's temporary folder where memfds are not
// available), and must throw on any error it sees; it may read its file back to check it. The
// bytes it produced then go to `file` through write_file_atomic, so every byte that reaches the
// destination is written with every write, the fsync and the rename checked, whatever the library
// does with its own write errors. Any failure throws an InputError naming `file` (never the
// in-memory name) and leaves nothing under `file`.
// " (files are limited to N bytes here: ulimit -f)" when a file size limit is set, else "": for
// messages about output a library could not complete.
std::string file_size_limit_note();

void write_via_memory_file(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write);

// The same in-memory file for a library that writes by name, when the bytes are wanted rather than a
// file (a thumbnail inside a JSON document): returns what `write(name)` left in it.
std::string bytes_via_memory_file(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write);

}  // namespace ofl
