// All-or-nothing file writes: the bytes go to a temporary file beside the target, which is
// renamed over the target only once everything was written and closed. On any failure (or
// if commit() is never reached, e.g. an exception unwinds) the temporary is removed, so
// the target is either untouched or complete. A symlink as target is written through: the
// file it points to is replaced and the link stays. No fsync: the guarantee is against our
// own failures (ENOSPC, EIO, exceptions), not against a power cut.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace gmpu::io {

class AtomicFile {
public:
    // Creates the temporary file. GMPU_ERROR_IO naming `path` if it cannot.
    explicit AtomicFile(std::string path);
    ~AtomicFile();  // removes the temporary unless commit() succeeded
    AtomicFile(const AtomicFile &) = delete;
    AtomicFile &operator=(const AtomicFile &) = delete;

    void write(const void *data, size_t size);  // buffered; GMPU_ERROR_IO on failure
    void write(std::string_view text) { write(text.data(), text.size()); }
    void commit();  // flush, close, rename over the target; GMPU_ERROR_IO on failure

    const std::string &path() const { return path_; }

private:
    void flush();
    [[noreturn]] void fail_io(const char *doing, int err);

    std::string path_;    // as given (messages)
    std::string target_;  // what is replaced: path_ with symlinks followed
    std::string temp_;
    int fd_ = -1;
    std::vector<char> buffer_;
    size_t used_ = 0;
    bool committed_ = false;
};

}  // namespace gmpu::io
