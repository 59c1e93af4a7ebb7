#include "common/base64.h"

#include <cstdint>

namespace common {
namespace {

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::uint32_t sextet(char c) {
  if (c >= 'A' && c <= 'Z') return std::uint32_t(c - 'A');
  if (c >= 'a' && c <= 'z') return std::uint32_t(c - 'a' + 26);
  if (c >= '0' && c <= '9') return std::uint32_t(c - '0' + 52);
  return c == '+' ? 62u : 63u;
}

}  // namespace

std::string base64_encode(std::string_view bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t left = bytes.size() - i;
    std::uint32_t group = std::uint32_t(std::uint8_t(bytes[i])) << 16;
    if (left > 1) group |= std::uint32_t(std::uint8_t(bytes[i + 1])) << 8;
    if (left > 2) group |= std::uint32_t(std::uint8_t(bytes[i + 2]));
    for (int k = 0; k < 4; ++k)
      out += k <= int(left) ? kAlphabet[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::string base64_decode(std::string_view text) {
  std::string out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i + 4 <= text.size(); i += 4) {
    std::uint32_t quad = 0;
    int bytes = 3;
    for (std::size_t k = 0; k < 4; ++k) {
      const bool pad = text[i + k] == '=';
      bytes -= pad ? 1 : 0;
      quad = (quad << 6) | (pad ? 0u : sextet(text[i + k]));
    }
    for (int k = 0; k < bytes; ++k) out += char((quad >> (16 - 8 * k)) & 0xFF);
  }
  return out;
}

}  // namespace common
