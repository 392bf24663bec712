// An input file opened for reading, checked before a byte is read: it must be a regular
// file (a FIFO would block the reader, /dev/zero never ends, a directory has no bytes), so
// its size is known and every reader's work is bounded by it. Readers pull its bytes in
// chunks (text formats) or whole (PLY, after its header was checked).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "io/read_ticker.hpp"
#include "io/text_scan.hpp"

namespace gmpu::io::detail {

class InputFile : public ByteSource {
public:
    // GMPU_ERROR_IO naming the path and the reason when it is missing, unreadable, a
    // directory or not a regular file.
    explicit InputFile(const std::string &path);
    ~InputFile() override;
    InputFile(const InputFile &) = delete;
    InputFile &operator=(const InputFile &) = delete;

    uint64_t size() const { return size_; }
    size_t read(char *dst, size_t n) override;  // 0 at the end; GMPU_ERROR_IO on failure
    uint64_t unread() const override { return consumed_ < size_ ? size_ - consumed_ : 0; }
    void rewind();

    // Appends the rest of the file to `bytes`.
    void read_rest(std::string &bytes);

    // Every read then reports the share of the file read so far (reads are at most a
    // 128 KiB each, so the reports keep their cadence).
    void set_ticker(const ReadTicker *ticker) { ticker_ = ticker; }

private:
    std::string path_;
    int fd_ = -1;
    uint64_t size_ = 0;
    uint64_t consumed_ = 0;
    const ReadTicker *ticker_ = nullptr;
};

// Lines of the file (line-based text formats), counted in one pass over it: what lets a
// reader reserve its arrays once instead of growing them. Leaves the file rewound. A line
// longer than LineReader::max_line_bytes is GMPU_ERROR_PARSE, found without reading on.
uint64_t count_lines(InputFile &file, const std::string &path);

}  // namespace gmpu::io::detail
