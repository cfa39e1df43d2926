#include "capture/sinks/output_path.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <stdexcept>
#include <system_error>

namespace arpipe {

namespace {

constexpr std::string_view kTemporaryInfix = ".new-";

// The pid in a temporary's name when it is one ("." + target + ".new-" + digits), and the target.
bool parse_temporary_name(std::string_view name, std::string_view& target, pid_t& pid) {
  if (name.size() < 2 || name[0] != '.') return false;
  const size_t infix = name.rfind(kTemporaryInfix);
  if (infix == std::string_view::npos || infix < 2) return false;
  const std::string_view digits = name.substr(infix + kTemporaryInfix.size());
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), pid);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || pid <= 0) return false;
  target = name.substr(1, infix - 1);
  return true;
}

bool process_runs(pid_t pid) { return ::kill(pid, 0) == 0 || errno != ESRCH; }

}  // namespace

void create_output_directory(const std::filesystem::path& dir, std::string_view config_key) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw std::runtime_error(fmt::format("{} (config {}): cannot create the output directory: {}", dir.string(),
                                         config_key, ec ? ec.message() : "a file of that name is in the way"));
}

void create_parent_directory(const std::filesystem::path& file, std::string_view config_key) {
  if (file.has_parent_path()) create_output_directory(file.parent_path(), config_key);
}

std::filesystem::path temporary_name(const std::filesystem::path& path) {
  return path.parent_path() / fmt::format(".{}{}{}", path.filename().string(), kTemporaryInfix, ::getpid());
}

void remove_stale_temporaries(const std::filesystem::path& dir,
                              const std::function<bool(std::string_view)>& ours) noexcept {
  try {
    std::error_code ec;
    for (auto it = std::filesystem::directory_iterator(dir.empty() ? "." : dir, ec);
         !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
      const std::string name = it->path().filename().string();
      std::string_view target;
      pid_t pid = 0;
      if (parse_temporary_name(name, target, pid) && ours(target) && !process_runs(pid)) {
        std::error_code ignored;
        std::filesystem::remove(it->path(), ignored);
      }
    }
  } catch (...) {  // a tidy-up: nothing depends on it
  }
}

bool sync_directory(const std::filesystem::path& dir) noexcept {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

int replace_file(const std::filesystem::path& path, std::span<const uint8_t> bytes) noexcept {
  std::filesystem::path temporary;
  try {
    temporary = temporary_name(path);
  } catch (...) {
    return ENOMEM;
  }
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) return errno;
  int error = 0;
  for (size_t done = 0; done < bytes.size() && !error;) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n > 0) done += size_t(n);
    else if (n < 0 && errno != EINTR) error = errno;
    else if (n == 0) error = EIO;
  }
  // Synced before the rename: after a power loss the name holds the whole picture or nothing.
  if (!error && ::fdatasync(fd) != 0) error = errno;
  if (::close(fd) != 0 && !error) error = errno;
  if (!error && ::rename(temporary.c_str(), path.c_str()) != 0) error = errno;
  if (error) ::unlink(temporary.c_str());
  return error;
}

}  // namespace arpipe
