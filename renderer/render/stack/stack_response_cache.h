// A content-addressed cache of tabulated stack responses on disk (transport "table",
// docs/layered-tissue.md "Cost"), so that the table of a layer stack is filled once per stack, not
// once per scene load: a sweep of LED placements, a rerun with more samples, the same preset in
// another scene all read it back.
//
// Where: $OFL_CACHE_DIR if set ("off" or empty: no cache), else $XDG_CACHE_HOME/oralfluor, else
// $HOME/.cache/oralfluor; entries in its stack-response/ folder, one file per stack and kind:
// <key>.ofltable (the position-free table) and <key>.oflprofile (the lateral profiles of the
// spatial transport, renderer/render/spatial/stack_profiles.h). The key hashes everything the fill reads (each layer's depths, index, anisotropy,
// absorption and scattering per bin, its fluorophores' absorption and re-emission matrices; the top
// interface's roughness and indices; the bottom; the base reflectance where the stack has one; the
// wavelength grid's size; the table options: nodes, walks, seed, bins walked, symmetrisation) and
// a hash of the source files of the walk and the fill (CMakeLists.txt, OFL_STACK_TRANSPORT_SOURCES),
// so that a table filled by an older walk is never read as current. The fill is deterministic, so
// an entry holds exactly the table a fresh fill would give (tests/test_layered_table.cpp checks it
// bit for bit).
//
// A table entry holds the elastic and fluorescent tables (not the LED-dependent sums, which are
// recomputed), a profile entry the ring masses and fluences; each the number of walks and the seconds the fill took. It is written atomically
// (write_file_atomic) and ends with a hash of its bytes; an entry that is cut short, corrupt, or of
// another format is ignored with a warning and overwritten by a fresh fill. A cache that cannot be
// written (read-only folder, full disk) costs a warning, never the render. Nothing is evicted: a
// table entry is 4 N^2 n (n + 1) bytes (N = 12 cosines, n wavelength bins: 5.3 MB at 97 bins), a
// profile entry about 5.7 MB at 97 bins; delete the folder to reclaim the space.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "renderer/render/material/material_tables.h"
#include "renderer/render/material/stack_tables.h"
#include "renderer/render/stack/stack_response_table.h"

namespace ofl {

// The cache folder from the environment (see above); empty when caching is off.
std::filesystem::path default_stack_cache_dir();

// A hash (32 hex digits) of everything a fill reads from a stack (layers, interfaces, bottom, base,
// grid size) and of the sources of the walk and the fills: the part of every entry's key that says
// which stack it is. Each kind of entry adds its own options.
std::string stack_content_key(const StackTables& st, const MaterialTables& mt, int n);

// The entry name of a stack's position-free table (32 hex digits).
std::string stack_response_key(const StackTables& st, const MaterialTables& mt, int n, const StackResponseOptions& opt);

// Kinds of entry (the file extension): the position-free table and the lateral profiles
// (renderer/render/spatial/stack_profiles.h).
inline const std::string kTableEntry = "ofltable", kProfileEntry = "oflprofile";

std::filesystem::path stack_cache_file(const std::filesystem::path& dir, const std::string& key,
                                       const std::string& kind = kTableEntry);

// An entry of float arrays. Loading fills `arrays`, which must already have the sizes the entry
// should hold; false when there is no entry, and false with a warning when it is unreadable, cut
// short, corrupt or of another size or format.
bool load_float_entry(const std::filesystem::path& dir, const std::string& key, const std::string& kind,
                      const std::vector<std::vector<float>*>& arrays, long long& walks, double& seconds, std::string& warning);
// Stores one atomically; a failure is returned as a warning (empty: stored).
std::string store_float_entry(const std::filesystem::path& dir, const std::string& key, const std::string& kind,
                              const std::vector<const std::vector<float>*>& arrays, long long walks, double seconds);

// The cached elastic and fluorescent tables (sums and LED terms not filled), or null when there is
// no entry; an unreadable or invalid entry gives null and a warning in `warning`.
std::shared_ptr<StackResponse> load_cached_stack_response(const std::filesystem::path& dir, const std::string& key,
                                                          int nodes, int n, std::string& warning);

// Stores a filled table; a failure is returned as a warning (empty: stored).
std::string store_stack_response(const std::filesystem::path& dir, const std::string& key, const StackResponse& r);

}  // namespace ofl
