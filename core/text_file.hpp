#pragma once
// Whole small text files: settings records, Markdown and CSV tables.
#include <string>

namespace yarnhom {

// The file's text ("" when it cannot be read or is not a regular file: a FIFO would block).
std::string read_text_file(const std::string& path);

// Written atomically (core/atomic_file.hpp); FileError(path, "", problem) when the write fails.
void write_text_file(const std::string& path, const std::string& text, const std::string& problem = "write failed");

}  // namespace yarnhom
