// Content hashes for caches: FNV-1a with the 128-bit parameters (offset basis
// 0x6c62272e07bb014262b821756295c58d, prime 2^88 + 0x13b), wide enough that two different inputs
// never share a name in practice. Not a cryptographic hash: it names cache entries, it does not
// defend against forged ones.
#pragma once
#include <cstddef>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

namespace ofl {

struct Fnv128 {
  using u128 = unsigned __int128;
  u128 h = (u128(0x6c62272e07bb0142ULL) << 64) | u128(0x62b821756295c58dULL);

  void add(const char* p, size_t n) {
    const u128 prime = (u128(1) << 88) | u128(0x13b);
    for (size_t i = 0; i < n; ++i) {
      h ^= u128(static_cast<unsigned char>(p[i]));
      h *= prime;
    }
  }
  // A number or flag by its bytes (the same value hashes the same on one machine).
  template <class T>
  void value(T v) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
    add(reinterpret_cast<const char*>(&v), sizeof v);
  }
  // An array by its length and bytes.
  template <class T>
  void values(const std::vector<T>& v) {
    static_assert(std::is_arithmetic_v<T>);
    value(v.size());
    add(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void text(const std::string& s) {
    value(s.size());
    add(s.data(), s.size());
  }
  // 32 hex digits.
  std::string hex() const {
    char b[33];
    std::snprintf(b, sizeof b, "%016llx%016llx", static_cast<unsigned long long>(h >> 64),
                  static_cast<unsigned long long>(h));
    return b;
  }
};

}  // namespace ofl
