#include "gltf/gltf_uri.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <deque>
#include <map>

#include <nlohmann/json.hpp>

#include "base/errors.h"
#include "base/input_file.h"
#include "gltf/tinygltf.h"

namespace vkray {
namespace {

std::string element(const char* array, size_t index) { return std::string(array) + "[" + std::to_string(index) + "]"; }

[[noreturn]] void fail(const std::filesystem::path& gltf_file, const std::string& where, const std::string& what) {
  throw SceneError(gltf_file.string() + ": " + where + ": " + what);
}

bool base64_digit(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/'; }

// The payload without its '=' padding, or empty when it is not base64 (RFC 4648, padded or not).
std::string_view base64_body(std::string_view payload) {
  std::string_view body = payload;
  while (!body.empty() && body.back() == '=' && payload.size() - body.size() < 2) body.remove_suffix(1);
  const bool padded = body.size() < payload.size();
  const bool whole = padded ? payload.size() % 4 == 0 : body.size() % 4 != 1;
  return whole && std::all_of(body.begin(), body.end(), base64_digit) ? body : std::string_view();
}

size_t base64_size(std::string_view payload) { return base64_body(payload).size() * 6 / 8; }

std::string lowered(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// A buffer tinygltf will ask the file callbacks for, and what vkray resolved its uri to.
struct BufferRequest {
  std::string name;            // "buffers[2] (mesh.bin)", for messages
  uint64_t byte_length = 0;    // what the file must hold
  std::string base64;          // a data: URI tinygltf does not decode itself, or
  std::filesystem::path file;  // the file the uri names
};

void check_image_uris(const nlohmann::json& doc, const std::filesystem::path& gltf_file) {
  if (!doc.contains("images")) return;
  const nlohmann::json& images = doc["images"];
  for (size_t i = 0; i < images.size(); ++i)
    if (images[i].contains("uri")) resolve_uri(images[i]["uri"].get<std::string>(), gltf_file, element("images", i) + ".uri");
}

}  // namespace

UriTarget resolve_uri(const std::string& uri, const std::filesystem::path& gltf_file, const std::string& where) {
  const std::string quoted = '"' + printable(uri, 200) + '"';
  if (uri.find('\0') != std::string::npos) fail(gltf_file, where, quoted + " holds a NUL character, which no file name can");
  // A scheme: a letter, then letters, digits, '+', '-' or '.', up to a ':' (RFC 3986, 3.1).
  const size_t colon = uri.find(':');
  const bool has_scheme = colon != std::string::npos && colon > 0 && std::isalpha(static_cast<unsigned char>(uri[0])) &&
                          std::all_of(uri.begin(), uri.begin() + std::ptrdiff_t(colon), [](char c) {
                            return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
                          });
  if (has_scheme) {
    if (lowered(uri.substr(0, colon)) != "data")
      fail(gltf_file, where,
           printable(uri.substr(0, colon + 1), 40) + " URIs are not read: vkray reads data: URIs and paths relative to the file");
    const size_t comma = uri.find(',');
    const std::string header = lowered(uri.substr(0, comma));
    if (comma == std::string::npos || header.size() < 7 || header.compare(header.size() - 7, 7, ";base64") != 0)
      fail(gltf_file, where, "a data: URI that is not base64; vkray reads data:<type>;base64,<data>");
    const std::string_view payload = std::string_view(uri).substr(comma + 1);
    if (base64_body(payload).empty()) fail(gltf_file, where, "a data: URI whose data is not base64, or is empty");
    return {payload, {}};
  }
  if (uri.rfind("//", 0) == 0) fail(gltf_file, where, quoted + " names a host; vkray reads data: URIs and paths relative to the file");
  // Percent-escapes decoded once, each to the byte it names.
  std::string path;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] != '%') {
      path += uri[i];
      continue;
    }
    if (i + 2 >= uri.size() || !std::isxdigit(static_cast<unsigned char>(uri[i + 1])) || !std::isxdigit(static_cast<unsigned char>(uri[i + 2])))
      fail(gltf_file, where, quoted + ": a '%' not followed by two hexadecimal digits");
    const char byte = char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
    if (byte == '\0')
      fail(gltf_file, where, quoted + ": %00 is a NUL character, which no file name can hold (the name would end there)");
    if (byte == '/' || byte == '\\')
      fail(gltf_file, where, quoted + ": %" + uri.substr(i + 1, 2) + " is an escaped separator, which would name another folder");
    path += byte;
    i += 2;
  }
  if (path.empty()) fail(gltf_file, where, "an empty uri names no file");
  return {{}, (gltf_file.parent_path() / path).lexically_normal()};
}

std::string decode_base64(std::string_view payload) {
  std::string out;
  out.reserve(base64_size(payload));
  uint32_t bits = 0;
  int count = 0;
  for (const char c : base64_body(payload)) {
    const uint32_t digit = c >= 'A' && c <= 'Z' ? uint32_t(c - 'A') : c >= 'a' && c <= 'z' ? uint32_t(c - 'a' + 26)
                         : c >= '0' && c <= '9' ? uint32_t(c - '0' + 52) : c == '+' ? 62u : 63u;
    bits = (bits << 6) | digit;
    if ((count += 6) >= 8) out += char((bits >> (count -= 8)) & 0xff);
  }
  return out;
}

// tinygltf's file callbacks: each request answered with what vkray resolved, read with vkray's
// checks (regular files, a size limit, Ctrl-C), or nothing at all.
struct GltfFiles::FileAccess {
  bool allowed = true;
  std::map<std::string, std::deque<BufferRequest>> requests;  // by the path tinygltf asks for (tinygltf_buffer_request)
  std::vector<std::filesystem::path> read;
  std::string error;  // the first failure, naming the buffer: reported instead of tinygltf's words

  // Every buffer's bytes resolved: its uri, or a .glb's binary chunk.
  void resolve_buffers(const nlohmann::json& doc, const std::filesystem::path& gltf_file, bool binary, bool has_binary_chunk);

  static bool file_exists(const std::string& path, void* user) { return static_cast<FileAccess*>(user)->requests.count(path) > 0; }
  static std::string expand_path(const std::string& path, void*) { return path; }  // no shell expansion (wordexp) for a file's URIs
  static bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user);
  static bool write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*);
};

void GltfFiles::FileAccess::resolve_buffers(const nlohmann::json& doc, const std::filesystem::path& gltf_file, bool binary,
                                            bool has_binary_chunk) {
  if (!doc.contains("buffers")) return;
  const std::string base_dir = gltf_file.parent_path().string();
  const nlohmann::json& buffers = doc["buffers"];
  for (size_t b = 0; b < buffers.size(); ++b) {
    const uint64_t byte_length = buffers[b]["byteLength"].get<uint64_t>();
    if (!buffers[b].contains("uri")) {
      // tinygltf would give every buffer without a uri the binary chunk.
      if (!binary) fail(gltf_file, element("buffers", b), "no uri: a .gltf file's buffers are files or data: URIs");
      if (b != 0) fail(gltf_file, element("buffers", b), "no uri: only buffers[0] of a .glb file is its binary chunk");
      if (!has_binary_chunk) fail(gltf_file, element("buffers", b), "no uri, and the .glb file has no binary chunk");
      continue;
    }
    const std::string& uri = buffers[b]["uri"].get_ref<const std::string&>();
    const UriTarget target = resolve_uri(uri, gltf_file, element("buffers", b) + ".uri");
    BufferRequest request{element("buffers", b) + " (" + printable(uri, 60) + ")", byte_length, "", target.file};
    if (target.data()) {
      if (base64_size(target.base64) != byte_length)
        fail(gltf_file, element("buffers", b),
             "its data: URI holds " + std::to_string(base64_size(target.base64)) + " bytes, and byteLength says " + std::to_string(byte_length));
      if (tinygltf::IsDataURI(uri)) continue;  // one tinygltf decodes itself, found strict base64 above
      request.base64 = std::string(target.base64);
    }
    requests[tinygltf_buffer_request(base_dir, uri)].push_back(std::move(request));
  }
}

bool GltfFiles::FileAccess::read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto* access = static_cast<FileAccess*>(user);
  const auto refuse = [&](const std::string& why) {
    if (access->error.empty()) access->error = why;
    if (err) *err += why + "\n";
    return false;
  };
  const auto found = access->requests.find(path);
  if (found == access->requests.end() || found->second.empty()) return refuse("tinygltf asked for a file vkray did not resolve: " + printable(path, 200));
  const BufferRequest request = std::move(found->second.front());
  found->second.pop_front();
  std::string bytes;
  if (!request.base64.empty()) {
    bytes = decode_base64(request.base64);
  } else {
    if (!access->allowed) return refuse(request.name + ": external files are not read here");
    InputFile input = read_input_file(request.file, kMaxGltfFileBytes);
    if (!input.error.empty()) return refuse(request.name + ": " + (input.error == "not found" ? "buffer file not found" : input.error));
    access->read.push_back(request.file);
    bytes = std::move(input.text);
  }
  if (bytes.size() != request.byte_length)
    return refuse(request.name + ": it holds " + std::to_string(bytes.size()) + " bytes, and byteLength says " + std::to_string(request.byte_length));
  out->assign(bytes.begin(), bytes.end());
  return true;
}

bool GltfFiles::FileAccess::write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "vkray writes no glTF files\n";
  return false;
}

GltfFiles::GltfFiles(const nlohmann::json& doc, const std::filesystem::path& gltf_file, bool read_files, bool binary,
                     bool has_binary_chunk)
    : access_(std::make_unique<FileAccess>()) {
  access_->allowed = read_files;
  access_->resolve_buffers(doc, gltf_file, binary, has_binary_chunk);
  check_image_uris(doc, gltf_file);
}

GltfFiles::~GltfFiles() = default;

tinygltf::FsCallbacks GltfFiles::callbacks() {
  return tinygltf::FsCallbacks{FileAccess::file_exists, FileAccess::expand_path, FileAccess::read_whole_file, FileAccess::write_whole_file,
                               access_.get()};
}

const std::string& GltfFiles::error() const { return access_->error; }

const std::vector<std::filesystem::path>& GltfFiles::read() const { return access_->read; }

}  // namespace vkray
