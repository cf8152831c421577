// fuzz/tools/make_gltf_seeds.cpp: the seed corpus of the gltf target (fuzz/corpus/gltf), written
// with the tests' glTF writer (tests/gltf_util.hpp): the textured cube as .gltf and .glb, and
// variants that reach each feature of the loader and the pbr shader. Built and run by
// make_seeds.sh.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "gltf_util.hpp"

using softrast::test::GltfParts;

namespace {

void save(const std::filesystem::path& dir, const std::string& name, const std::string& bytes) {
  std::ofstream(dir / name, std::ios::binary) << bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_gltf_seeds OUT_DIR\n");
    return 2;
  }
  std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  std::string png = softrast::test::checker_png((dir / "checker_tmp.png").string());
  std::filesystem::remove(dir / "checker_tmp.png");
  GltfParts cube = softrast::test::textured_cube(png);
  save(dir, "cube.gltf", softrast::test::as_gltf(cube));
  save(dir, "cube.glb", softrast::test::as_glb(cube));

  GltfParts features = cube;  // every material feature on one primitive
  nlohmann::json& m = features.json["materials"][0];
  m["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
      {"KHR_texture_transform", {{"offset", {0.5, 0.0}}, {"rotation", 0.3}, {"scale", {2, 2}}}}};
  m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", 0}};
  m["normalTexture"] = {{"index", 0}, {"scale", 0.5}};
  m["occlusionTexture"] = {{"index", 0}, {"strength", 0.7}, {"texCoord", 1}};
  m["emissiveTexture"] = {{"index", 0}};
  m["emissiveFactor"] = {1.0, 0.5, 0.0};
  m["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", 3.0}}}};
  m["alphaMode"] = "MASK";
  m["alphaCutoff"] = 0.6;
  m["doubleSided"] = true;
  features.json["extensionsUsed"] = {"KHR_texture_transform", "KHR_materials_emissive_strength"};
  features.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = 2;
  save(dir, "features.glb", softrast::test::as_glb(features));

  GltfParts blend = cube;  // blended, colours per vertex, a matrix node, a triangle strip
  blend.json["materials"][0]["alphaMode"] = "BLEND";
  blend.json["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 0.5};
  std::vector<float> colors(24 * 4, 0.5f);
  int c =
      softrast::test::add_accessor(blend, softrast::test::float_bytes(colors), 5126, 24, "VEC4");
  blend.json["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = c;
  blend.json["meshes"][0]["primitives"][0]["mode"] = 5;
  blend.json["nodes"][1] = {{"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1}},
                            {"mesh", 0}};
  save(dir, "blend.gltf", softrast::test::as_gltf(blend));

  GltfParts bare = cube;  // no indices, no normals, no material, no scene: defaults everywhere
  bare.json["meshes"][0]["primitives"][0].erase("indices");
  bare.json["meshes"][0]["primitives"][0].erase("material");
  bare.json["meshes"][0]["primitives"][0]["attributes"].erase("NORMAL");
  bare.json.erase("scene");
  bare.json.erase("scenes");
  bare.png.clear();
  bare.json.erase("textures");
  bare.json.erase("materials");
  bare.json.erase("samplers");
  save(dir, "bare.gltf", softrast::test::as_gltf(bare));

  GltfParts quantized = cube;  // KHR_mesh_quantization: normalised unsigned byte uvs
  std::string uvs;
  for (int i = 0; i < 24; ++i) uvs += std::string{char(i * 10), char(255 - i * 10)};
  int q = softrast::test::add_accessor(quantized, uvs, 5121, 24, "VEC2");
  quantized.json["accessors"][q]["normalized"] = true;
  quantized.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = q;
  quantized.json["extensionsRequired"] = {"KHR_mesh_quantization"};
  quantized.json["extensionsUsed"] = {"KHR_mesh_quantization"};
  save(dir, "quantized.glb", softrast::test::as_glb(quantized));
  return 0;
}
