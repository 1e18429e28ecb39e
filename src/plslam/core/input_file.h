#pragma once
// Opening a file the user names: every reader goes through here, so a missing file, a folder in
// its place or an unreadable file gives the same one-line InputError naming it.
#include <filesystem>
#include <fstream>
#include <string>

namespace plslam {

// Opens `path` for reading in binary mode; a missing path says `missing` ("file not found"
// unless given), a folder in its place says so.
std::ifstream open_input_file(const std::filesystem::path& path, const char* missing = "file not found");

// open_input_file, then skips a UTF-8 byte-order mark (Windows editors write one), so text files
// saved on Windows read like the others.
std::ifstream open_text_file(const std::filesystem::path& path, const char* missing = "file not found");

// Removes the '\r' of a CRLF line ending.
void strip_cr(std::string& line);

}  // namespace plslam
