// An EXR file's header checked against the file itself before OpenEXR reads it for pixels. OpenEXR
// believes a header: it allocates what an attribute's size, a preview's size, the data window, the
// channel list or a block of scan lines claims, and it follows every offset in the chunk offset
// table, so a file of a few bytes could ask for gigabytes or send it reading past its end. Here the
// header is walked attribute by attribute on the bytes of the open file, and every claim is checked
// against the file's size and vkray's limits first; only then does read_exr (exr_read.cpp) hand the
// same open file to OpenEXR.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace vkray {

// Checks the header of `in`, the open file `file` of `file_bytes` bytes, from its first byte: the
// magic number and version (single-part, flat), each attribute's size and a preview image's within
// the file, the data window (at most kMaxImageSide on a side), the channel list (at most
// kMaxExrChannels, with R, G and B, the ones read not subsampled), the compression or tile size, a
// block of scan lines OpenEXR decodes at once, and the chunk offset table (in the file, every offset
// within it). Returns the scan lines to read at a time: whole blocks, at least 64 lines. Leaves `in`
// at an unspecified place. Throws InputError naming the file; OpenEXR's own exceptions for what its
// header parser refuses.
int check_exr_header(std::ifstream& in, const std::filesystem::path& file, uint64_t file_bytes);

// Throws InputError "FILE: why".
[[noreturn]] void refuse_exr(const std::filesystem::path& file, const std::string& why);

}  // namespace vkray
