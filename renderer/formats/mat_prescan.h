// A bounds check of a MAT 5 file before libmatio reads it. libmatio allocates what a variable's
// dimensions ask for before it looks at the data behind them (fuzz_mat: a 1.8 kB file made it
// allocate 1.7 GB). This walks the data elements itself - inflating compressed ones under the
// memory limit - and requires every numeric or character array's data to hold the elements its
// dimensions claim, and every cell and struct to hold a tag for each of its elements.
#pragma once
#include <filesystem>

namespace ofl {

// Throws InputError naming the file and variable when a size does not fit; does nothing for files
// that are not little- or big-endian MAT 5 (libmatio reports those itself).
void check_mat5_sizes(const std::filesystem::path& file);

// The same for a MAT 4 file (no file header; each variable a 20-byte header of type, rows,
// columns, imaginary flag and name length, then the name and the data), run before libmatio opens
// the file: libmatio allocates the name length it reads while probing for MAT 4 (fuzz_mat: a
// 22-byte file made it allocate 1.8 GB). Every name and data size must fit in the file. Does
// nothing for MAT 5 files (the "IM"/"MI" marker at byte 126) and for what is not MAT 4 either.
void check_mat4_sizes(const std::filesystem::path& file);

}  // namespace ofl
