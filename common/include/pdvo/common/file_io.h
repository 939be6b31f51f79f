// Small file helpers shared by every tool: atomic writes, reading whole files, reading images with clear
// errors.
#pragma once

#include <opencv2/core/mat.hpp>
#include <string>

namespace pdvo {

// Writes `content` to a temporary file beside `path`, then renames it over `path`, so a crash never leaves
// a half-written file. Creates missing parent folders. Throws IoError naming the file.
void WriteFileAtomically(const std::string& path, const std::string& content);

// Reads a whole file; throws IoError naming the file if it is missing or unreadable.
std::string ReadFile(const std::string& path);

// Reads an image (cv::IMREAD_* flags); throws IoError naming the file if it is missing, empty or cannot be
// decoded (e.g. truncated).
cv::Mat ReadImage(const std::string& path, int flags);

// Encodes an image by the extension of `path` (.png, .jpg, ...) and writes it atomically.
void WriteImage(const std::string& path, const cv::Mat& image);

// Throws IoError naming `path` if it does not exist.
void CheckExists(const std::string& path, const std::string& what = "file");

}  // namespace pdvo
