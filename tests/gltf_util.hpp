// tests/gltf_util.hpp: glTF 2.0 files written by the tests: a textured cube in a two-node
// hierarchy and a grid of spheres (metallic x roughness), as .gltf (buffer and image in data
// URIs) or .glb (both in the BIN chunk), with the JSON open to changes for the bad-input cases.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "softrast/image.hpp"

namespace softrast::test {

// A scene before it is written: the JSON (buffers[0] and the image filled in by as_gltf/as_glb),
// the binary buffer and an optional PNG for image 0.
struct GltfParts {
  nlohmann::json json;
  std::string bin;
  std::string png;
  size_t index_offset = 0;  // where the first index (uint16) is in `bin`
};

inline std::string base64(const std::string& bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 2]));
    out += k[v >> 18 & 63];
    out += k[v >> 12 & 63];
    out += i + 1 < bytes.size() ? k[v >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

inline void append_floats(std::string& bin, const std::vector<float>& values) {
  bin.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
}

// Adds a bufferView and an accessor over `bytes` appended to bin; returns the accessor index.
inline int add_accessor(GltfParts& g, const std::string& bytes, int component_type, int count,
                        const char* type, const nlohmann::json& min = nullptr,
                        const nlohmann::json& max = nullptr) {
  while (g.bin.size() % 4) g.bin += '\0';
  int view = int(g.json["bufferViews"].size());
  g.json["bufferViews"].push_back(
      {{"buffer", 0}, {"byteOffset", g.bin.size()}, {"byteLength", bytes.size()}});
  g.bin += bytes;
  nlohmann::json a = {
      {"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
  if (!min.is_null()) a["min"] = min, a["max"] = max;
  int index = int(g.json["accessors"].size());
  g.json["accessors"].push_back(a);
  return index;
}

inline std::string float_bytes(const std::vector<float>& v) {
  std::string s;
  append_floats(s, v);
  return s;
}

inline std::string u16_bytes(const std::vector<uint16_t>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * 2);
}

inline std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A 4x4 PNG: a red/white checker with a blue top-left texel (so a flip would show).
inline std::string checker_png(const std::string& scratch_path) {
  Image image(4, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      uint8_t* p = &image.rgba[size_t(y * 4 + x) * 4];
      bool white = (x + y) % 2 == 0;
      p[0] = 255, p[1] = white ? 255 : 40, p[2] = white ? 255 : 40, p[3] = 255;
      if (x == 0 && y == 0) p[0] = 30, p[1] = 60, p[2] = 255;
    }
  }
  if (!save_image(scratch_path, image).ok()) return {};
  return read_bytes(scratch_path);
}

// A unit cube (24 vertices with normals and uvs, 36 uint16 indices) as mesh 0, drawn by node 1,
// the child of node 0: node 0 translates by (0.25, 0, 0), node 1 turns by 30 degrees about y and
// scales by 0.8. Material 0: the checker texture (image 0), metallic 0, roughness 0.5.
inline GltfParts textured_cube(const std::string& png) {
  GltfParts g;
  g.png = png;
  g.json = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", {0}}}}},
            {"bufferViews", nlohmann::json::array()},
            {"accessors", nlohmann::json::array()}};
  std::vector<float> p, n, uv;
  std::vector<uint16_t> idx;
  const float faces[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int f = 0; f < 6; ++f) {
    float nx = faces[f][0], ny = faces[f][1], nz = faces[f][2];
    // Two axes across the face, so that u x v = the normal (counter-clockwise from outside).
    float ux = nz, uy = 0, uz = -nx;  // (nz, 0, -nx), or x on the two y faces
    if (ny != 0) ux = 1, uy = 0, uz = 0;
    float vx = ny * uz - nz * uy, vy = nz * ux - nx * uz, vz = nx * uy - ny * ux;  // n x u
    uint16_t base = uint16_t(p.size() / 3);
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const auto& c : corners) {
      p.insert(p.end(), {0.5f * (nx + c[0] * ux + c[1] * vx), 0.5f * (ny + c[0] * uy + c[1] * vy),
                         0.5f * (nz + c[0] * uz + c[1] * vz)});
      n.insert(n.end(), {nx, ny, nz});
      uv.insert(uv.end(), {0.5f + 0.5f * c[0], 0.5f - 0.5f * c[1]});  // glTF: v down
    }
    idx.insert(idx.end(), {base, uint16_t(base + 1), uint16_t(base + 2), base, uint16_t(base + 2),
                           uint16_t(base + 3)});
  }
  int pos = add_accessor(g, float_bytes(p), 5126, 24, "VEC3", {-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  int nrm = add_accessor(g, float_bytes(n), 5126, 24, "VEC3");
  int tex = add_accessor(g, float_bytes(uv), 5126, 24, "VEC2");
  while (g.bin.size() % 4) g.bin += '\0';
  g.index_offset = g.bin.size();
  int ind = add_accessor(g, u16_bytes(idx), 5123, 36, "SCALAR");
  g.json["meshes"] = {{{"primitives",
                        {{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", tex}}},
                          {"indices", ind},
                          {"material", 0}}}}}};
  g.json["materials"] = {{{"pbrMetallicRoughness",
                           {{"baseColorTexture", {{"index", 0}}},
                            {"metallicFactor", 0.0},
                            {"roughnessFactor", 0.5}}}}};
  g.json["textures"] = {{{"source", 0}, {"sampler", 0}}};
  g.json["samplers"] = {{{"magFilter", 9728}, {"minFilter", 9728}}};  // nearest: crisp texels
  const float s = std::sin(0.5f * 0.5235988f), c = std::cos(0.5f * 0.5235988f);
  g.json["nodes"] = {{{"translation", {0.25, 0.0, 0.0}}, {"children", {1}}},
                     {{"rotation", {0.0, s, 0.0, c}}, {"scale", {0.8, 0.8, 0.8}}, {"mesh", 0}}};
  return g;
}

// The scene as .gltf text: buffer 0 and image 0 as base64 data URIs.
inline std::string as_gltf(GltfParts g) {
  g.json["buffers"] = {{{"byteLength", g.bin.size()},
                        {"uri", "data:application/octet-stream;base64," + base64(g.bin)}}};
  if (!g.png.empty()) g.json["images"] = {{{"uri", "data:image/png;base64," + base64(g.png)}}};
  return g.json.dump(1);
}

// The scene as .glb: the PNG appended to the binary buffer as a bufferView of its own.
inline std::string as_glb(GltfParts g) {
  if (!g.png.empty()) {
    while (g.bin.size() % 4) g.bin += '\0';
    int view = int(g.json["bufferViews"].size());
    g.json["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", g.bin.size()}, {"byteLength", g.png.size()}});
    g.bin += g.png;
    g.json["images"] = {{{"bufferView", view}, {"mimeType", "image/png"}}};
  }
  while (g.bin.size() % 4) g.bin += '\0';
  g.json["buffers"] = {{{"byteLength", g.bin.size()}}};
  std::string json = g.json.dump();
  while (json.size() % 4) json += ' ';
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  std::string out = "glTF" + u32(2) + u32(uint32_t(12 + 8 + json.size() + 8 + g.bin.size()));
  out += u32(uint32_t(json.size())) + "JSON" + json;
  out += u32(uint32_t(g.bin.size())) + std::string("BIN\0", 4) + g.bin;
  return out;
}

// A UV sphere of radius 0.4 (rings x segments quads) as mesh 0, drawn by `columns` x `rows` nodes
// one unit apart; node (i, j) has material j * columns + i with metallic j / (rows - 1) (down
// the image: rows further down are more metallic) and roughness i / (columns - 1) (left to right).
inline GltfParts sphere_grid(int columns, int rows, float r, float g_, float b) {
  GltfParts g;
  g.json = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", {}}}}},
            {"bufferViews", nlohmann::json::array()},
            {"accessors", nlohmann::json::array()}};
  const int rings = 24, segments = 48;
  std::vector<float> p, n;
  std::vector<uint16_t> idx;
  for (int i = 0; i <= rings; ++i) {
    float theta = 3.14159265f * float(i) / rings;
    for (int j = 0; j <= segments; ++j) {
      float phi = 2.0f * 3.14159265f * float(j) / segments;
      float x = std::sin(theta) * std::cos(phi), y = std::cos(theta),
            z = -std::sin(theta) * std::sin(phi);
      p.insert(p.end(), {0.4f * x, 0.4f * y, 0.4f * z});
      n.insert(n.end(), {x, y, z});
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      uint16_t a = uint16_t(i * (segments + 1) + j), c = uint16_t(a + segments + 1);
      idx.insert(idx.end(), {a, c, uint16_t(a + 1), uint16_t(a + 1), c, uint16_t(c + 1)});
    }
  }
  int count = int(p.size() / 3);
  int pos =
      add_accessor(g, float_bytes(p), 5126, count, "VEC3", {-0.4, -0.4, -0.4}, {0.4, 0.4, 0.4});
  int nrm = add_accessor(g, float_bytes(n), 5126, count, "VEC3");
  int ind = add_accessor(g, u16_bytes(idx), 5123, int(idx.size()), "SCALAR");
  g.json["meshes"] = nlohmann::json::array();
  g.json["materials"] = nlohmann::json::array();
  g.json["nodes"] = nlohmann::json::array();
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      int m = j * columns + i;
      g.json["materials"].push_back(
          {{"pbrMetallicRoughness",
            {{"baseColorFactor", {r, g_, b, 1.0}},
             {"metallicFactor", rows > 1 ? double(j) / (rows - 1) : 0.0},
             {"roughnessFactor", columns > 1 ? double(i) / (columns - 1) : 0.5}}}});
      g.json["meshes"].push_back({{"primitives",
                                   {{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}},
                                     {"indices", ind},
                                     {"material", m}}}}});
      g.json["nodes"].push_back(
          {{"mesh", m},
           {"translation", {double(i) - 0.5 * (columns - 1), 0.5 * (rows - 1) - double(j), 0.0}}});
      g.json["scenes"][0]["nodes"].push_back(m);
    }
  }
  return g;
}

}  // namespace softrast::test
