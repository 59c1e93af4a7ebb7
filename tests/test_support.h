// tests/test_support.h: helpers shared by the test suites (scratch files, byte patching of
// binary files, the damaged-file harness, quadrature).
#pragma once

#include "common/hash.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include <sys/resource.h>

namespace test_support {

// A cube of side 2 about the origin as OBJ text: 8 positions and 12 triangles, wound
// counter-clockwise from outside. With `normals`, six 'vn' records (one per face, in the
// order -Z +Z -Y +Y -X +X) and every corner written v//vn.
inline std::string cube_obj(bool normals) {
  std::string out =
      "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
      "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n";
  if (normals) out += "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n";
  const int faces[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5},
                           {4, 8, 7, 3}, {1, 5, 8, 4}, {2, 3, 7, 6}};
  for (int f = 0; f < 6; ++f) {
    for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
      out += "f";
      for (int c : tri) {
        out += ' ';
        out += std::to_string(faces[f][c]);
        if (normals) {
          out += "//";
          out += std::to_string(f + 1);
        }
      }
      out += "\n";
    }
  }
  return out;
}

// A path in this suite's scratch directory (created on first use).
inline std::filesystem::path scratch(const std::string& suite, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(PRTR_TEST_TMPDIR) / suite;
  std::filesystem::create_directories(dir);
  return dir / name;
}

// Writes `content` (bytes as they are) to `name` in `suite`'s scratch directory.
inline std::filesystem::path write_scratch(const std::string& suite, const std::string& name,
                                           const std::string& content) {
  const std::filesystem::path p = scratch(suite, name);
  std::ofstream(p, std::ios::binary) << content;
  return p;
}

// The message of the `Error` that `f()` throws; a test failure (and "") when it throws none.
template <class Error, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a " << typeid(Error).name();
  return {};
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The value of type T stored at `offset` in a file's bytes (read by memcpy: unaligned).
template <class T>
T peek(const std::string& bytes, std::size_t offset) {
  if (offset + sizeof(T) > bytes.size()) throw std::out_of_range("peek past the end");
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

// Overwrites sizeof(T) bytes at `offset` in place, as a damaged or forged file would have.
// Throws rather than asserting so that it works in helpers that return values.
template <class T>
void patch(const std::filesystem::path& p, std::size_t offset, T value) {
  std::fstream f(p, std::ios::in | std::ios::out | std::ios::binary);
  if (!f) throw std::runtime_error("cannot open " + p.string() + " to patch it");
  f.seekp(std::streamoff(offset));
  f.write(reinterpret_cast<const char*>(&value), sizeof(T));
  if (!f) throw std::runtime_error("cannot patch " + p.string());
}

// The message of the `Error` that `read(p)` throws, checked to name the file and to contain
// `expected`; a test failure (and "") when it throws nothing.
template <class Error, class Read>
std::string error_of(const std::filesystem::path& p, Read read, const std::string& expected) {
  try {
    read(p);
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(p.string()), std::string::npos) << "message does not name the file: " << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << "expected '" << expected << "' in: " << msg;
    return msg;
  }
  ADD_FAILURE() << p << ": expected an error mentioning '" << expected << "'";
  return {};
}

// "Each kind of damage has its own message", the harness of the file-format suites: each
// damaged file's message is recorded under the kind of damage; at the end no two kinds may
// share a message once the file name (everything up to the first ": ") is taken out, and
// exactly `kinds` must have been tried, so a case that silently stops running is noticed.
class DamageMessages {
 public:
  void record(const std::string& kind, const std::string& message) { messages_[kind] = message; }

  void expect_distinct(std::size_t kinds) const {
    std::set<std::string> problems;
    for (const auto& [kind, msg] : messages_) {
      const std::size_t colon = msg.find(": ");
      ASSERT_NE(colon, std::string::npos) << kind << ": " << msg;
      EXPECT_TRUE(problems.insert(msg.substr(colon + 2)).second) << kind << " repeats: " << msg;
    }
    EXPECT_EQ(messages_.size(), kinds);
  }

 private:
  std::map<std::string, std::string> messages_;  // kind -> message
};

// Recomputes a header checksum (FNV-1a of the bytes before it, stored at `checksum_offset`),
// so that a patched field is caught by its own check rather than by the checksum.
inline void reseal_header(const std::filesystem::path& p, std::size_t checksum_offset) {
  const std::string bytes = slurp(p);
  patch<std::uint64_t>(p, checksum_offset, common::fnv1a(bytes.data(), checksum_offset));
}

// Bitwise equality of two arrays. memcmp must not see the null data() of an empty vector
// (undefined behaviour even for a zero length), so empty arrays are compared by size alone.
inline bool same_bytes(const void* a, const void* b, std::size_t bytes) {
  return bytes == 0 || std::memcmp(a, b, bytes) == 0;
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n); exact for polynomials of
// degree < 2n. The oracle quadrature of the SH and bake tests.
inline void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

// RLIMIT_FSIZE makes write(2) fail with EFBIG part-way through a file, as on a full disk: a
// real failed write. For the whole process (every thread) until the end of the scope.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = old_;
    limit.rlim_cur = std::min(bytes, old_.rlim_max);
    ok_ = setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = SIG_DFL;
  bool ok_ = false;
};

}  // namespace test_support
