#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <limits.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <chrono>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "io/errors.hpp"

namespace gmpu::io {

namespace {

constexpr size_t buffer_size = size_t{1} << 20;

// Distinguishes temporaries of concurrent writers in one process; the pid distinguishes
// processes, and O_EXCL catches whatever is left.
std::atomic<unsigned> temp_counter{0};

// The temporary's name: the target's name, cut short if need be so that the whole stays
// within NAME_MAX (a 250-character target name is legal; its temporary must be too), then
// ".tmp-gmpu-PID-N".
std::string temp_name(const std::string &path, unsigned long pid, unsigned n) {
    char suffix[64];
    std::snprintf(suffix, sizeof suffix, ".tmp-gmpu-%lu-%u", pid, n);
    const size_t slash = path.find_last_of('/');
    const size_t base_start = slash == std::string::npos ? 0 : slash + 1;
    const size_t room = NAME_MAX - std::strlen(suffix);
    const size_t base_len = std::min(path.size() - base_start, room);
    return path.substr(0, base_start + base_len) + suffix;
}

// The file a write to `path` replaces: when `path` is a symlink (or a chain of them), the
// file it points to, so that the link stays and its target gets the new bytes (what an
// editor does). A dangling link names the file to create.
std::string write_target(const std::string &path) {
    std::string cur = path;
    for (int hops = 0; hops < 40; ++hops) {
        struct stat st;
        if (::lstat(cur.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return cur;
        std::string link(PATH_MAX, '\0');
        const ssize_t n = ::readlink(cur.c_str(), &link[0], link.size());
        if (n <= 0 || static_cast<size_t>(n) == link.size()) return cur;  // the write reports the problem
        link.resize(static_cast<size_t>(n));
        const size_t slash = cur.find_last_of('/');
        cur = link[0] == '/' || slash == std::string::npos ? link : cur.substr(0, slash + 1) + link;
    }
    detail::fail(GMPU_ERROR_IO, path, "cannot write: " + detail::system_reason(ELOOP));
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)), target_(write_target(path_)) {
    // Beside the target (same directory, so same file system: rename() is atomic) and
    // hidden-ish, so a directory listing during the write shows what is going on.
    // open(O_EXCL, 0666) rather than mkstemp so the final file gets the usual umask
    // permissions instead of mkstemp's 0600.
    const auto pid = static_cast<unsigned long>(::getpid());
    unsigned n = temp_counter.fetch_add(1);
    for (int attempt = 0; attempt < 100; ++attempt) {
        temp_ = temp_name(target_, pid, n);
        fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd_ >= 0) break;
        if (errno != EEXIST) {
            int err = errno;
            temp_.clear();  // nothing to remove
            detail::fail(GMPU_ERROR_IO, path_, "cannot create file: " + detail::system_reason(err));
        }
        // Taken: a leftover of a killed process that had our pid, or of an earlier write
        // in this one. Leftovers come in runs of consecutive numbers, so jump well away.
        const auto ticks = static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
        n = temp_counter.fetch_add(1) + static_cast<unsigned>(ticks * 2654435761u);  // unsigned: wraps
    }
    if (fd_ < 0) {
        temp_.clear();
        detail::fail(GMPU_ERROR_IO, path_, "cannot create a temporary file beside it");
    }
    buffer_.resize(buffer_size);
}

AtomicFile::~AtomicFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_ && !temp_.empty()) ::unlink(temp_.c_str());
}

void AtomicFile::fail_io(const char *doing, int err) {
    // Close and remove now rather than in the destructor, so that the failure is complete
    // by the time the caller sees the exception.
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (!temp_.empty()) ::unlink(temp_.c_str());
    temp_.clear();
    detail::fail(GMPU_ERROR_IO, path_, std::string(doing) + ": " + detail::system_reason(err));
}

void AtomicFile::flush() {
    size_t done = 0;
    while (done < used_) {
        ssize_t n = ::write(fd_, buffer_.data() + done, used_ - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            fail_io("cannot write", errno);
        }
        done += static_cast<size_t>(n);
    }
    used_ = 0;
}

void AtomicFile::write(const void *data, size_t size) {
    if (fd_ < 0) detail::fail(GMPU_ERROR_INTERNAL, path_, "write after failure or commit");
    const char *bytes = static_cast<const char *>(data);
    while (size > 0) {
        if (used_ == buffer_.size()) flush();
        size_t n = std::min(size, buffer_.size() - used_);
        std::memcpy(buffer_.data() + used_, bytes, n);
        used_ += n;
        bytes += n;
        size -= n;
    }
}

void AtomicFile::commit() {
    if (fd_ < 0) detail::fail(GMPU_ERROR_INTERNAL, path_, "commit after failure or commit");
    flush();
    // close() can report a deferred write error (NFS, quota): check it.
    int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) fail_io("cannot write", errno);
    if (::rename(temp_.c_str(), target_.c_str()) != 0) fail_io("cannot replace", errno);
    committed_ = true;
}

}  // namespace gmpu::io
