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

}  // namespace ofl
