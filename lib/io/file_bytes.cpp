#include "io/file_bytes.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "io/errors.hpp"

namespace gmpu::io::detail {

namespace {

// Closes the descriptor on every path out, including exceptions.
struct Fd {
    int fd;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

}  // namespace

std::string read_file_bytes(const std::string &path) {
    Fd file{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
    if (file.fd < 0) fail(GMPU_ERROR_IO, path, "cannot open: " + system_reason(errno));
    struct stat st;
    if (::fstat(file.fd, &st) != 0) fail(GMPU_ERROR_IO, path, "cannot stat: " + system_reason(errno));
    // open() succeeds on a directory; say so now rather than fail on the first read.
    if (S_ISDIR(st.st_mode)) fail(GMPU_ERROR_IO, path, "cannot read: " + system_reason(EISDIR));

    // The size is only a hint (pipes have none, files may change while read): read to EOF.
    std::string data;
    data.resize(S_ISREG(st.st_mode) ? static_cast<size_t>(st.st_size) + 1 : 65536);
    size_t got = 0;
    for (;;) {
        if (got == data.size()) data.resize(data.size() * 2);
        ssize_t n = ::read(file.fd, &data[got], data.size() - got);
        if (n < 0) {
            if (errno == EINTR) continue;
            fail(GMPU_ERROR_IO, path, "cannot read: " + system_reason(errno));
        }
        if (n == 0) break;
        got += static_cast<size_t>(n);
    }
    data.resize(got);
    return data;
}

}  // namespace gmpu::io::detail
