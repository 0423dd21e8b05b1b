#include "support/test_assets.h"

#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <png.h>
#include <turbojpeg.h>

namespace vkray::test {

TestPicture four_colours() { return {2, 2, {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255}}; }

std::string png_bytes(const TestPicture& picture) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = picture.width;
  image.height = picture.height;
  image.format = PNG_FORMAT_RGB;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&image, nullptr, &size, 0, picture.rgb.data(), 0, nullptr)) throw std::runtime_error(image.message);
  std::string out(size, '\0');
  if (!png_image_write_to_memory(&image, out.data(), &size, 0, picture.rgb.data(), 0, nullptr)) throw std::runtime_error(image.message);
  out.resize(size);
  return out;
}

std::string jpeg_bytes(const TestPicture& picture, int quality) {
  const std::unique_ptr<void, int (*)(tjhandle)> handle(tjInitCompress(), tjDestroy);
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  if (tjCompress2(handle.get(), picture.rgb.data(), int(picture.width), 0, int(picture.height), TJPF_RGB, &jpeg, &size, TJSAMP_444,
                  quality, TJFLAG_ACCURATEDCT) != 0)
    throw std::runtime_error(tjGetErrorStr2(handle.get()));
  std::string out(reinterpret_cast<const char*>(jpeg), size);
  tjFree(jpeg);
  return out;
}

std::string png_header_only(uint32_t width, uint32_t height) {
  std::string out("\x89PNG\r\n\x1a\n", 8);
  const auto be32 = [&](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out += char((v >> s) & 0xff);
  };
  be32(13);
  const size_t type_at = out.size();
  out += "IHDR";
  be32(width);
  be32(height);
  out += std::string("\x08\x02\x00\x00\x00", 5);  // 8-bit RGB
  uint32_t crc = 0xffffffffu;  // CRC-32 of type and data, as PNG defines it
  for (size_t i = type_at; i < out.size(); ++i) {
    crc ^= uint8_t(out[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  be32(~crc);
  // An empty IDAT and the IEND: a reader stops at the header's size, before any pixel data.
  out += std::string("\x00\x00\x00\x00IDAT\x35\xaf\x06\x1e", 12);
  out += std::string("\x00\x00\x00\x00IEND\xae\x42\x60\x82", 12);
  return out;
}

void write_file(const std::filesystem::path& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

namespace {

std::string base64(const std::string& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    uint32_t n = uint32_t(uint8_t(data[i])) << 16;
    if (i + 1 < data.size()) n |= uint32_t(uint8_t(data[i + 1])) << 8;
    if (i + 2 < data.size()) n |= uint8_t(data[i + 2]);
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += i + 1 < data.size() ? table[(n >> 6) & 63] : '=';
    out += i + 2 < data.size() ? table[n & 63] : '=';
  }
  return out;
}

}  // namespace

GltfBuilder::GltfBuilder() {
  doc = {{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", nlohmann::json::array()}}}}};
}

static int append_view(GltfBuilder& b, const std::string& bytes) {
  while (b.bin.size() % 4) b.bin += '\0';
  b.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", b.bin.size()}, {"byteLength", bytes.size()}});
  b.bin += bytes;
  return int(b.doc["bufferViews"].size()) - 1;
}

int GltfBuilder::accessor(const std::vector<float>& values, const char* type) {
  const int components = std::string(type) == "VEC2" ? 2 : std::string(type) == "VEC3" ? 3 : std::string(type) == "VEC4" ? 4 : 1;
  const int view = append_view(*this, std::string(reinterpret_cast<const char*>(values.data()), values.size() * 4));
  doc["accessors"].push_back({{"bufferView", view}, {"componentType", 5126}, {"count", values.size() / size_t(components)}, {"type", type}});
  return int(doc["accessors"].size()) - 1;
}

int GltfBuilder::indices(const std::vector<uint32_t>& values, int component_type) {
  std::string bytes;
  for (const uint32_t v : values) {
    const size_t size = component_type == 5121 ? 1 : component_type == 5123 ? 2 : 4;
    bytes.append(reinterpret_cast<const char*>(&v), size);  // little-endian
  }
  const int view = append_view(*this, bytes);
  doc["accessors"].push_back({{"bufferView", view}, {"componentType", component_type}, {"count", values.size()}, {"type", "SCALAR"}});
  return int(doc["accessors"].size()) - 1;
}

int GltfBuilder::quad(int material, bool indexed) {
  nlohmann::json primitive;
  if (indexed) {
    primitive["attributes"] = {{"POSITION", accessor({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3")},
                               {"TEXCOORD_0", accessor({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2")}};
    primitive["indices"] = indices({0, 1, 2, 0, 2, 3});
  } else {
    primitive["attributes"] = {{"POSITION", accessor({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3")},
                               {"TEXCOORD_0", accessor({0, 1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0}, "VEC2")}};
  }
  if (material >= 0) primitive["material"] = material;
  doc["meshes"].push_back({{"primitives", {primitive}}});
  doc["nodes"].push_back({{"mesh", int(doc["meshes"].size()) - 1}});
  const int node = int(doc["nodes"].size()) - 1;
  doc["scenes"][0]["nodes"].push_back(node);
  return node;
}

int GltfBuilder::material(const nlohmann::json& m) {
  doc["materials"].push_back(m);
  return int(doc["materials"].size()) - 1;
}

int GltfBuilder::texture(const std::string& picture, const nlohmann::json& sampler) {
  const int view = append_view(*this, picture);
  doc["images"].push_back({{"bufferView", view}, {"mimeType", picture.rfind("\x89PNG", 0) == 0 ? "image/png" : "image/jpeg"}});
  nlohmann::json texture = {{"source", int(doc["images"].size()) - 1}};
  if (!sampler.is_null()) {
    doc["samplers"].push_back(sampler);
    texture["sampler"] = int(doc["samplers"].size()) - 1;
  }
  doc["textures"].push_back(texture);
  return int(doc["textures"].size()) - 1;
}

std::string GltfBuilder::gltf() const {
  nlohmann::json d = doc;
  if (!bin.empty()) d["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
  return d.dump();
}

std::string GltfBuilder::glb() const {
  nlohmann::json d = doc;
  if (!bin.empty()) d["buffers"] = {{{"byteLength", bin.size()}}};
  std::string json = d.dump();
  while (json.size() % 4) json += ' ';
  std::string chunk_bin = bin;
  while (chunk_bin.size() % 4) chunk_bin += '\0';
  std::string out;
  const auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  const uint32_t total = uint32_t(12 + 8 + json.size() + (chunk_bin.empty() ? 0 : 8 + chunk_bin.size()));
  out += "glTF";
  u32(2);
  u32(total);
  u32(uint32_t(json.size()));
  u32(0x4E4F534Au);
  out += json;
  if (!chunk_bin.empty()) {
    u32(uint32_t(chunk_bin.size()));
    u32(0x004E4942u);
    out += chunk_bin;
  }
  return out;
}

}  // namespace vkray::test
