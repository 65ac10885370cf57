// A stdio stream whose write(2) calls run on a thread of their own: the code that formats a file fills the
// stream's buffer while the previous buffers are copied into the kernel.
//
// Why: at IMU rate a run writes about 170 MB of outputs per hour of log. Copying them into the page cache
// costs a few hundredths of a second when the kernel's pages are warm, and more than the formatting itself
// when they are not (measured on a virtual machine whose free memory the host had taken back): on the
// formatting thread that copy set the ESKF's wall time. Memory is bounded: besides the stream's buffer, at
// most two copies of it, one being written and one waiting (core/io/batch_pipe.h).
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace gins {

// Opens `path` for writing (created or truncated, like fopen's "wb"), buffered by `buffer` (the caller's,
// `size` bytes, outliving the stream). Returns nullptr with errno set if the file cannot be created.
// fclose() waits for every write and returns EOF, with errno, if any write or the close failed; a failed
// write drops the rest of the file's data (the stream reports it only at fclose, not at fwrite).
FILE* OpenBackgroundWriteStream(const std::string& path, char* buffer, size_t size);

}  // namespace gins
