// The checksum of checkpoint data (docs/reliability.md, "Damaged checkpoints"): FNV-1a with 64 bits
// over bytes, the same function as proto::scene_hash. Each step of FNV-1a (xor a byte into the state,
// multiply by an odd prime modulo 2^64) is a bijection of the state, so a change confined to any one
// byte always changes the result; other damage goes unseen with a probability of about 2^-64.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace hfmpm {

inline constexpr std::uint64_t kFnv1a64Start = 14695981039346656037ull;

// `hash` continues a checksum over earlier bytes (kFnv1a64Start for none).
inline std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash = kFnv1a64Start) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 1099511628211ull;
  }
  return hash;
}

inline std::uint64_t fnv1a64(const std::string& bytes) { return fnv1a64(bytes.data(), bytes.size()); }

// 16 lowercase hex digits.
inline std::string checksum_text(std::uint64_t hash) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string text(16, '0');
  for (int i = 15; i >= 0; --i, hash >>= 4) text[static_cast<std::size_t>(i)] = kDigits[hash & 0xf];
  return text;
}

}  // namespace hfmpm
