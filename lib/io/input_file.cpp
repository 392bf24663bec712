#include "io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "io/errors.hpp"

namespace gmpu::io::detail {

namespace {

const char *kind_of(mode_t mode) {
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

}  // namespace

InputFile::InputFile(const std::string &path) : path_(path) {
    // O_NONBLOCK: opening a FIFO must not wait for a writer; the check below rejects it.
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd_ < 0) fail(GMPU_ERROR_IO, path, "cannot open: " + system_reason(errno));
    struct stat st;
    if (::fstat(fd_, &st) != 0) {
        const int err = errno;
        ::close(fd_);
        fail(GMPU_ERROR_IO, path, "cannot stat: " + system_reason(err));
    }
    if (!S_ISREG(st.st_mode)) {
        ::close(fd_);
        if (S_ISDIR(st.st_mode)) fail(GMPU_ERROR_IO, path, "cannot read: " + system_reason(EISDIR));
        fail(GMPU_ERROR_IO, path, std::string("cannot read: ") + kind_of(st.st_mode) + ", not a regular file");
    }
    // Regular files never block; clear the flag anyway so reads behave as usual.
    ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_NONBLOCK);
    size_ = static_cast<uint64_t>(st.st_size);
}

namespace {
// One read's most: a text reader parses this much in about ten milliseconds, between two
// progress polls.
constexpr size_t kMaxRead = size_t{128} << 10;
}  // namespace

InputFile::~InputFile() {
    if (fd_ >= 0) ::close(fd_);
}

size_t InputFile::read(char *dst, size_t n) {
    n = std::min(n, kMaxRead);
    for (;;) {
        const ssize_t got = ::read(fd_, dst, n);
        if (got >= 0) {
            consumed_ += static_cast<uint64_t>(got);
            if (ticker_) ticker_->at(size_ > 0 ? std::min(1.0, double(consumed_) / double(size_)) : 1.0);
            return static_cast<size_t>(got);
        }
        if (errno != EINTR) fail(GMPU_ERROR_IO, path_, "cannot read: " + system_reason(errno));
    }
}

void InputFile::rewind() {
    if (::lseek(fd_, 0, SEEK_SET) != 0) fail(GMPU_ERROR_IO, path_, "cannot seek: " + system_reason(errno));
    consumed_ = 0;
}

void InputFile::read_rest(std::string &bytes) {
    // The size is a hint (the file may change while read): read to the end regardless.
    // Appended a chunk at a time, so that the pages are touched (and faulted in) between
    // two reads, not all at once by a resize.
    bytes.reserve(bytes.size() + static_cast<size_t>(unread()));
    std::vector<char> chunk(kMaxRead);
    while (const size_t n = read(chunk.data(), chunk.size())) bytes.append(chunk.data(), n);
}

uint64_t count_lines(InputFile &file, const std::string &path) {
    std::vector<char> chunk(size_t{1} << 20);
    uint64_t lines = 0, line_start = 0, offset = 0;
    char last = '\n';
    while (const size_t n = file.read(chunk.data(), chunk.size())) {
        for (const char *p = chunk.data(), *end = p + n;
             (p = static_cast<const char *>(std::memchr(p, '\n', static_cast<size_t>(end - p)))); ++p) {
            ++lines;
            line_start = offset + static_cast<uint64_t>(p - chunk.data()) + 1;
        }
        offset += n;
        last = chunk[n - 1];
        // Stop at the first overlong line, as the parser would: a file without newlines
        // (binary data, a sparse file) must not be read whole.
        if (offset - line_start > LineReader::max_line_bytes)
            fail(GMPU_ERROR_PARSE, path, "line " + std::to_string(lines + 1) + " is longer than " +
                                             std::to_string(LineReader::max_line_bytes >> 20) + " MiB (not a text file?)");
    }
    file.rewind();
    return lines + (last != '\n');  // a last line without its newline counts too
}

}  // namespace gmpu::io::detail
