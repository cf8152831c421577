// io/gltf_document.hpp: reading a glTF 2.0 document (JSON or GLB) into tinygltf's model, with the
// checks tinygltf leaves out done first (GLB framing, data URIs, buffer files, required
// extensions). io/gltf_loader.cpp turns the model into a Mesh.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_FS
#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "softrast/image.hpp"
#include "softrast/mesh.hpp"
#include "softrast/status.hpp"

namespace softrast::detail {

// The extensions a file may require (extensionsRequired) and still be drawn correctly.
bool gltf_extension_supported(const std::string& name);

// A parsed document and the images its bufferViews and data URIs hold, decoded (external image
// files are left to the caller: their uri stays in model.images[i].uri).
struct GltfDocument {
  tinygltf::Model model;
  std::vector<std::shared_ptr<Image>> images;  // per model.images index; null: not decoded here
  std::vector<std::string> warnings;
};

// Parses the glTF (JSON) or GLB bytes of `name`; external buffers are read relative to
// `base_dir` (empty: no file may be read, as for the fuzzer). Errors are one line, "name: ...".
Result<GltfDocument> read_gltf_document(const uint8_t* data, size_t size, const std::string& name,
                                        const std::string& base_dir);

// Reads every accessor of the document as floats (the fuzzer's check that none reads out of
// bounds, used by a mesh or not); the first error, or ok.
Status gltf_read_every_accessor(const GltfDocument& doc);

// Turns a document into a mesh (io/gltf_loader.cpp); `base_dir` as above, for image files.
Result<Mesh> gltf_to_mesh(GltfDocument& doc, const std::string& name, const std::string& base_dir);

}  // namespace softrast::detail
