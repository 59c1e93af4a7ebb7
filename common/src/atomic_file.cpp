#include "common/atomic_file.h"

#include "common/output_path.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>
#include <random>
#include <string_view>

namespace common {
namespace {

std::string errno_text() {
  return std::strerror(errno);
}

constexpr std::string_view kTempMarker = ".tmp-";
constexpr auto kAlwaysStaleAfter = std::chrono::hours(24);

// The pid in ".<name>.tmp-<pid>-<n>" or ".<name>.tmp-<pid>-<n>.<ext>" (see temporary_path),
// or 0 when `file` is not named like our temporaries.
pid_t temporary_owner(const std::string& file) {
  if (file.size() < 2 || file[0] != '.') return 0;
  const std::size_t marker = file.rfind(kTempMarker);
  if (marker == std::string::npos || marker < 2) return 0;
  std::string_view rest = std::string_view(file).substr(marker + kTempMarker.size());
  const std::size_t dash = rest.find('-');
  if (dash == std::string_view::npos || dash == 0 || dash + 1 == rest.size()) return 0;
  long pid = 0;
  const auto [end, ec] = std::from_chars(rest.data(), rest.data() + dash, pid);
  if (ec != std::errc() || end != rest.data() + dash || pid <= 0) return 0;
  rest.remove_prefix(dash + 1);
  // An extension, letters and digits only, may follow the number.
  if (const std::size_t dot = rest.find('.'); dot != std::string_view::npos) {
    const std::string_view ext = rest.substr(dot + 1);
    const auto alnum = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; };
    if (ext.empty() || !std::all_of(ext.begin(), ext.end(), alnum)) return 0;
    rest = rest.substr(0, dot);
  }
  unsigned long suffix = 0;
  const auto [end2, ec2] = std::from_chars(rest.data(), rest.data() + rest.size(), suffix);
  if (rest.empty() || ec2 != std::errc() || end2 != rest.data() + rest.size()) return 0;
  return static_cast<pid_t>(pid);
}

bool process_gone(pid_t pid) {
  return ::kill(pid, 0) != 0 && errno == ESRCH;
}

}  // namespace

std::vector<std::filesystem::path> sweep_stale_temporaries(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::vector<fs::path> removed;
  std::error_code ec;
  fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec);
  if (ec) return removed;
  const auto now = fs::file_time_type::clock::now();
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) break;
    const pid_t owner = temporary_owner(it->path().filename().string());
    if (owner == 0 || owner == ::getpid()) continue;
    std::error_code file_ec;
    if (!it->is_regular_file(file_ec)) continue;
    const auto written = it->last_write_time(file_ec);
    const bool old = !file_ec && now - written > kAlwaysStaleAfter;
    if ((old || process_gone(owner)) && fs::remove(it->path(), file_ec)) {
      removed.push_back(it->path());
    }
  }
  return removed;
}

std::filesystem::path temporary_path(const std::filesystem::path& target, bool keep_extension) {
  static thread_local std::mt19937 engine(std::random_device{}());
  // Built with append: GCC 12 reports a false -Wrestrict on chained operator+ here.
  std::string name = ".";
  name.append(target.filename().string())
      .append(kTempMarker)
      .append(std::to_string(::getpid()))
      .append("-")
      .append(std::to_string(engine() & 0xffffff));
  if (keep_extension) name.append(target.extension().string());
  return (target.has_parent_path() ? target.parent_path() : std::filesystem::path(".")) / name;
}

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  const std::filesystem::path dir =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    throw IoError(target_.string() + ": directory " + dir.string() +
                  " does not exist; create it first or choose another output path");
  }
  // Earlier runs killed mid-write leave their temporaries here; this is the first moment we
  // know the directory is in use again.
  sweep_stale_temporaries(dir);
  // A unique name in the same directory, so the final rename stays on one file system.
  for (int attempt = 0; attempt < 16 && fd_ < 0; ++attempt) {
    temp_ = temporary_path(target_);
    fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd_ < 0 && errno != EEXIST) break;
  }
  if (fd_ < 0) {
    throw IoError(target_.string() + ": cannot create a temporary file in " + dir.string() + " (" +
                  errno_text() + ")");
  }
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::write(const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd_, p, bytes);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(target_.string() + ": write failed (" + errno_text() + ")");
    }
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
}

void AtomicFile::commit() {
  if (::fsync(fd_) != 0) throw IoError(target_.string() + ": fsync failed (" + errno_text() + ")");
  if (::close(fd_) != 0) {
    fd_ = -1;
    throw IoError(target_.string() + ": close failed (" + errno_text() + ")");
  }
  fd_ = -1;
  check_output_target(target_);
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    throw IoError(target_.string() + ": cannot replace the file (" + errno_text() + ")");
  }
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& target, const void* data,
                           std::size_t bytes) {
  AtomicFile file(target);
  file.write(data, bytes);
  file.commit();
}

}  // namespace common
