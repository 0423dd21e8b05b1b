// Where a glTF file's buffers and pictures are: each uri resolved by vkray, never by tinygltf.
// tinygltf decodes a uri by its own rules ('+' read as a space, as in a web form; a bad escape read
// as a NUL) and, when its file is not in the glTF file's folder, looks for it in the working
// directory, so the file it opened need not be the one the uri names. vkray decodes each uri once
// by RFC 3986, refuses one that names no file it can read, and answers tinygltf's file callbacks
// with the file (or data) it resolved, and nothing else.
//
// A uri is a data: URI in base64, or a relative reference (RFC 3986) resolved against the glTF file's
// folder with its percent-escapes decoded once: a subfolder, "..", or an absolute path, as a scene
// file's paths may be. Refused, naming the key: a NUL, raw or as %00 (the file opened would be the
// name cut short there); an escaped separator, %2F or %5C (a folder the name did not have); a '%'
// without two hex digits; a scheme other than data: (http:, file:, ...) or a host ("//host/x"); a
// data: URI that is not base64 or holds no bytes.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace tinygltf {
struct FsCallbacks;
}

namespace vkray {

struct UriTarget {
  std::string_view base64;     // a data: URI's payload, checked to be base64 (points into the uri), or
  std::filesystem::path file;  // the file the uri names
  bool data() const { return !base64.empty(); }
};

// Resolves the uri at `where` ("images[2].uri") of `gltf_file`. Throws SceneError naming both.
UriTarget resolve_uri(const std::string& uri, const std::filesystem::path& gltf_file, const std::string& where);

// The bytes of a data: URI's payload (UriTarget::base64).
std::string decode_base64(std::string_view payload);

// The buffers tinygltf will read, each resolved to a file or data before it parses, and served to
// it through its file callbacks: regular files, a size limit and Ctrl-C checked as vkray reads any
// file, and each buffer's size held to its byteLength. No other path is read: not tinygltf's second
// guess in the working directory, nor a name decoded by its rules.
class GltfFiles {
 public:
  // Resolves every buffer's uri (or, in a .glb, the binary chunk buffers[0] takes without one) and
  // checks every picture's uri, in a document check_gltf_schema has passed. `binary`: a .glb file.
  // `read_files`: whether buffer files are read at all (data: URIs always are). Throws SceneError
  // naming the key.
  GltfFiles(const nlohmann::json& doc, const std::filesystem::path& gltf_file, bool read_files, bool binary, bool has_binary_chunk);
  ~GltfFiles();
  GltfFiles(const GltfFiles&) = delete;
  GltfFiles& operator=(const GltfFiles&) = delete;

  // For tinygltf::TinyGLTF::SetFsCallbacks; valid while this object lives.
  tinygltf::FsCallbacks callbacks();
  // The first buffer that could not be read, named, to report instead of tinygltf's words; empty
  // when none failed.
  const std::string& error() const;
  // The buffer files read so far.
  const std::vector<std::filesystem::path>& read() const;

 private:
  struct FileAccess;
  std::unique_ptr<FileAccess> access_;
};

}  // namespace vkray
