// io/gltf_loader.cpp: load_gltf. Turns TinyGLTF's model into one Mesh: every accessor checked
// against its bufferView and buffer before a byte is read or an element allocated, the default
// scene's nodes walked once each (the hierarchy must be a forest), each primitive instance
// transformed to world space and appended as a SubMesh, each glTF material a Material with `pbr`.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "io/gltf_document.hpp"
#include "io/model_formats.hpp"

namespace softrast {
namespace detail {
namespace {

namespace tg = tinygltf;

Status fail(const std::string& what, const std::string& reason) {
  return Status::error(what + ": " + reason);
}

std::string n(uint64_t v) {
  return std::to_string(v);
}

// ---- Accessors ------------------------------------------------------------------------------

int component_bytes(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

// The glTF name of an accessor type (tinygltf's code), for messages.
std::string type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "an unknown type";
  }
}

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    default:
      return 0;  // matrices are not vertex attributes softrast reads
  }
}

// The bytes [offset, offset + length) of bufferView `view`, checked to lie inside the view and the
// view inside its buffer.
Result<const uint8_t*> view_bytes(const tg::Model& m, int view, uint64_t offset, uint64_t length,
                                  const std::string& what) {
  if (view < 0 || size_t(view) >= m.bufferViews.size()) {
    return fail(what, "bufferView " + std::to_string(view) + " does not exist");
  }
  const tg::BufferView& v = m.bufferViews[size_t(view)];
  std::string view_what = "bufferView " + std::to_string(view);
  if (v.buffer < 0 || size_t(v.buffer) >= m.buffers.size()) {
    return fail(view_what, "buffer " + std::to_string(v.buffer) + " does not exist");
  }
  const std::vector<unsigned char>& data = m.buffers[size_t(v.buffer)].data;
  if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset) {
    return fail(view_what, "bytes " + n(v.byteOffset) + " + " + n(v.byteLength) +
                               " run past its buffer's " + n(data.size()));
  }
  if (offset > v.byteLength || length > v.byteLength - offset) {
    return fail(what, "bytes " + n(offset) + " + " + n(length) + " run past " + view_what + "'s " +
                          n(v.byteLength) + " bytes");
  }
  return data.data() + v.byteOffset + offset;
}

// Where an accessor's elements are: checked to lie inside the view and the view inside its buffer.
// Without a bufferView the elements are zeros (`first` null), as glTF defines. A sparse accessor
// then replaces the elements its strictly increasing indices name by its tightly packed values.
struct AccessorBytes {
  const uint8_t* first = nullptr;  // null: every element is zero
  size_t stride = 0;
  size_t count = 0;
  int components = 0;
  int component_type = 0;
  bool normalized = false;
  size_t sparse_count = 0;
  const uint8_t* sparse_indices = nullptr;
  int sparse_index_bytes = 0;  // 1, 2 or 4
  const uint8_t* sparse_values = nullptr;
};

template <class T>
T load_as(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// The k-th index of a sparse accessor.
uint32_t sparse_index(const AccessorBytes& a, size_t k) {
  const uint8_t* p = a.sparse_indices + k * size_t(a.sparse_index_bytes);
  return a.sparse_index_bytes == 1   ? load_as<uint8_t>(p)
         : a.sparse_index_bytes == 2 ? load_as<uint16_t>(p)
                                     : load_as<uint32_t>(p);
}

Result<AccessorBytes> locate(const tg::Model& m, int index, const std::vector<int>& allowed_types,
                             uint64_t max_count) {
  std::string what = "accessor " + std::to_string(index);
  if (index < 0 || size_t(index) >= m.accessors.size()) return fail(what, "does not exist");
  const tg::Accessor& a = m.accessors[size_t(index)];
  AccessorBytes r;
  r.components = type_components(a.type);
  r.component_type = a.componentType;
  r.normalized = a.normalized;
  int bytes = component_bytes(a.componentType);
  if (std::find(allowed_types.begin(), allowed_types.end(), r.components) == allowed_types.end()) {
    // allowed_types: component counts, 1 to 4 (SCALAR, VEC2, VEC3, VEC4).
    std::string expected;
    for (int components : allowed_types) {
      expected += (expected.empty() ? "" : " or ") +
                  (components == 1 ? std::string("SCALAR") : "VEC" + std::to_string(components));
    }
    return fail(what, "is " + type_name(a.type) + " where " + expected + " is expected");
  }
  if (bytes == 0) return fail(what, "unknown componentType " + std::to_string(a.componentType));
  if (a.count > max_count) {
    return fail(what, "count " + n(a.count) + " is over the limit of " + n(max_count));
  }
  r.count = a.count;
  uint64_t element = uint64_t(r.components) * uint64_t(bytes);
  if (a.bufferView >= 0) {  // without one, zeros
    if (size_t(a.bufferView) >= m.bufferViews.size()) {
      return fail(what, "bufferView " + std::to_string(a.bufferView) + " does not exist");
    }
    const tg::BufferView& v = m.bufferViews[size_t(a.bufferView)];
    Result<const uint8_t*> view = view_bytes(m, a.bufferView, 0, 0, what);
    if (!view) return view.status();
    r.stride = v.byteStride ? v.byteStride : size_t(element);
    if (r.stride < element) {
      return fail(what,
                  "byteStride " + n(r.stride) + " is less than its element (" + n(element) + ")");
    }
    if (r.count > 0) {
      // offset + (count - 1) * stride + element <= byteLength, without overflow.
      uint64_t length = v.byteLength;
      bool fits = a.byteOffset <= length && element <= length - a.byteOffset &&
                  (r.count - 1) <= (length - a.byteOffset - element) / r.stride;
      if (!fits) {
        return fail(what, n(r.count) + " elements of " + n(element) + " bytes (stride " +
                              n(r.stride) + ") from byte " + n(a.byteOffset) +
                              " run past bufferView " + std::to_string(a.bufferView) + "'s " +
                              n(length) + " bytes");
      }
      r.first = *view + a.byteOffset;
    }
  }
  if (!a.sparse.isSparse) return r;
  const std::string sparse_what = what + ": sparse";
  if (a.sparse.count < 1 || uint64_t(a.sparse.count) > r.count) {
    return fail(sparse_what,
                "count " + std::to_string(a.sparse.count) + " is not in 1.." + n(r.count));
  }
  r.sparse_count = size_t(a.sparse.count);
  switch (a.sparse.indices.componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      r.sparse_index_bytes = component_bytes(a.sparse.indices.componentType);
      break;
    default:
      return fail(sparse_what, "indices must be unsigned integers");
  }
  if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0) {
    return fail(sparse_what, "negative byteOffset");
  }
  Result<const uint8_t*> indices = view_bytes(
      m, a.sparse.indices.bufferView, uint64_t(a.sparse.indices.byteOffset),
      uint64_t(r.sparse_count) * uint64_t(r.sparse_index_bytes), sparse_what + " indices");
  if (!indices) return indices.status();
  Result<const uint8_t*> values =
      view_bytes(m, a.sparse.values.bufferView, uint64_t(a.sparse.values.byteOffset),
                 uint64_t(r.sparse_count) * element, sparse_what + " values");
  if (!values) return values.status();
  r.sparse_indices = *indices;
  r.sparse_values = *values;
  for (size_t k = 0; k < r.sparse_count; ++k) {
    uint32_t i = sparse_index(r, k);
    if (i >= r.count || (k > 0 && i <= sparse_index(r, k - 1))) {
      return fail(sparse_what, "index " + n(i) + " at " + n(k) +
                                   " is out of range or not increasing (count " + n(r.count) + ")");
    }
  }
  return r;
}

// Element i's bytes: its sparse value if it has one (`next_sparse` walks the sparse indices in
// order as i increases), else the base element, or null for a zero element.
const uint8_t* element_at(const AccessorBytes& a, size_t i, size_t& next_sparse) {
  if (next_sparse < a.sparse_count && sparse_index(a, next_sparse) == i) {
    size_t element = size_t(a.components) * size_t(component_bytes(a.component_type));
    return a.sparse_values + next_sparse++ * element;
  }
  return a.first ? a.first + i * a.stride : nullptr;
}

// One component as a float: normalised integers by glTF's rules, others converted.
float component(const AccessorBytes& a, const uint8_t* p) {
  switch (a.component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return load_as<float>(p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      float c = float(load_as<int8_t>(p));
      return a.normalized ? std::max(c / 127.0f, -1.0f) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      float c = float(load_as<uint8_t>(p));
      return a.normalized ? c / 255.0f : c;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      float c = float(load_as<int16_t>(p));
      return a.normalized ? std::max(c / 32767.0f, -1.0f) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      float c = float(load_as<uint16_t>(p));
      return a.normalized ? c / 65535.0f : c;
    }
    default:  // UNSIGNED_INT
      return float(load_as<uint32_t>(p));
  }
}

// Reads an accessor as `width` floats per element (missing components filled from `fill`).
Status read_floats(const tg::Model& m, int index, const std::vector<int>& types, int width,
                   glm::vec4 fill, std::vector<glm::vec4>& out) {
  Result<AccessorBytes> a = locate(m, index, types, uint64_t(kMaxGltfVertices));
  if (!a) return a.status();
  int bytes = component_bytes(a->component_type);
  out.assign(a->count, fill);
  size_t next_sparse = 0;
  for (size_t i = 0; i < a->count; ++i) {
    const uint8_t* p = element_at(*a, i, next_sparse);
    for (int c = 0; c < std::min(a->components, width); ++c)
      out[i][c] = p ? component(*a, p + c * bytes) : 0.0f;
  }
  return {};
}

Status read_indices(const tg::Model& m, int index, std::vector<uint32_t>& out) {
  Result<AccessorBytes> a = locate(m, index, {1}, uint64_t(3) * uint64_t(kMaxGltfTriangles));
  if (!a) return a.status();
  int type = a->component_type;
  if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    return fail("accessor " + std::to_string(index), "indices must be unsigned integers");
  }
  out.resize(a->count);
  size_t next_sparse = 0;
  for (size_t i = 0; i < a->count; ++i) {
    const uint8_t* p = element_at(*a, i, next_sparse);
    out[i] = p == nullptr                                     ? 0u
             : type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE  ? load_as<uint8_t>(p)
             : type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? load_as<uint16_t>(p)
                                                              : load_as<uint32_t>(p);
  }
  return {};
}

// ---- Materials ------------------------------------------------------------------------------

Wrap wrap_of(int mode) {
  if (mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return Wrap::kClampToEdge;
  if (mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return Wrap::kMirroredRepeat;
  return Wrap::kRepeat;
}

Sampler sampler_of(const tg::Model& m, int index) {
  Sampler s;
  s.filter = Filter::kTrilinear;  // unspecified: the best softrast has
  if (index < 0 || size_t(index) >= m.samplers.size()) return s;
  const tg::Sampler& t = m.samplers[size_t(index)];
  if (t.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) s.filter = Filter::kNearest;
  if (t.minFilter == TINYGLTF_TEXTURE_FILTER_LINEAR) s.filter = Filter::kBilinear;
  if (t.minFilter == -1 && t.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST)
    s.filter = Filter::kNearest;
  s.wrap_u = wrap_of(t.wrapS);
  s.wrap_v = wrap_of(t.wrapT);
  return s;
}

double number(const tg::Value& v, const char* key, double fallback) {
  if (!v.IsObject() || !v.Has(key)) return fallback;
  const tg::Value& x = v.Get(key);
  if (!x.IsNumber()) return fallback;
  double d = x.GetNumberAsDouble();
  return std::isfinite(d) ? d : fallback;
}

glm::vec2 pair(const tg::Value& v, const char* key, glm::vec2 fallback) {
  if (!v.IsObject() || !v.Has(key)) return fallback;
  const tg::Value& a = v.Get(key);
  if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber()) {
    return fallback;
  }
  glm::vec2 r(float(a.Get(0).GetNumberAsDouble()), float(a.Get(1).GetNumberAsDouble()));
  return std::isfinite(r.x) && std::isfinite(r.y) ? r : fallback;
}

// KHR_texture_transform, given in glTF's uv convention (v down), as a map of softrast's uvs
// (v up): with F(u, v) = (u, 1 - v), uv' = F(offset + R * S * F(uv)).
void apply_texture_transform(const tg::ExtensionMap& extensions, TextureSlot& slot) {
  auto it = extensions.find("KHR_texture_transform");
  if (it == extensions.end()) return;
  const tg::Value& t = it->second;
  glm::vec2 offset = pair(t, "offset", glm::vec2(0.0f));
  glm::vec2 scale = pair(t, "scale", glm::vec2(1.0f));
  float rotation = float(number(t, "rotation", 0.0));
  double tex_coord = number(t, "texCoord", -1.0);
  if (tex_coord == 0.0 || tex_coord == 1.0) slot.uv_set = int(tex_coord);
  float c = std::cos(rotation), s = std::sin(rotation);
  // A = R * S with R = [c s; -s c] (rows): uv' = (c u + s v, -s u + c v) before the offset.
  // This is the direction the extension's examples and Khronos's TextureTransformTest model
  // require ("offset [0, 1], rotation pi/2, scale 0.5: the lower left quadrant, rotated
  // clockwise 90 degrees"); the GLSL snippet of the extension's text, read as GLSL's
  // column-major mat3, turns the other way (the sample model's red marker).
  float a00 = c * scale.x, a01 = s * scale.y, a10 = -s * scale.x, a11 = c * scale.y;
  // uv' = D A D uv + D (A (0, 1) + offset) + (0, 1), D = diag(1, -1).
  slot.u_row = {a00, -a01, a01 + offset.x};
  slot.v_row = {-a10, a11, 1.0f - (a11 + offset.y)};
  slot.transformed = true;
}

struct TextureCache {
  const tg::Model* model;
  GltfDocument* doc;
  std::string name, base_dir;
  std::map<int, std::shared_ptr<const Texture>> textures;  // by image index
  std::vector<std::string>* warnings;

  std::shared_ptr<const Texture> image(int index) {
    if (auto it = textures.find(index); it != textures.end()) return it->second;
    std::shared_ptr<const Texture>& t = textures[index];
    Result<Image> decoded = decode(index);
    if (decoded) {
      t = std::make_shared<Texture>(Texture::from_image(*decoded));
    } else {
      warnings->push_back(decoded.status().message() + "; drawn without this texture");
    }
    return t;
  }

  Result<Image> decode(int index) {
    std::string what = name + ": image " + std::to_string(index);
    if (index < 0 || size_t(index) >= model->images.size()) return fail(what, "does not exist");
    if (doc->images[size_t(index)]) return *doc->images[size_t(index)];
    const tg::Image& img = model->images[size_t(index)];
    if (img.bufferView >= 0) {
      if (size_t(img.bufferView) >= model->bufferViews.size()) return fail(what, "no bufferView");
      const tg::BufferView& v = model->bufferViews[size_t(img.bufferView)];
      if (v.buffer < 0 || size_t(v.buffer) >= model->buffers.size()) return fail(what, "no buffer");
      const std::vector<unsigned char>& data = model->buffers[size_t(v.buffer)].data;
      if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset) {
        return fail(what, "its bufferView runs past the buffer");
      }
      return decode_image(data.data() + v.byteOffset, v.byteLength, what);
    }
    if (img.uri.empty() || img.uri.rfind("data:", 0) == 0) return fail(what, "not decoded");
    if (base_dir.empty()) return fail(what, "external image files are not read here");
    return load_image((std::filesystem::path(base_dir) / img.uri).string());
  }

  TextureSlot slot(int texture, int tex_coord, const tg::ExtensionMap& extensions) {
    TextureSlot s;
    if (texture < 0 || size_t(texture) >= model->textures.size()) return s;
    const tg::Texture& t = model->textures[size_t(texture)];
    if (t.source < 0) return s;
    s.texture = image(t.source);
    s.sampler = sampler_of(*model, t.sampler);
    s.uv_set = tex_coord == 1 ? 1 : 0;
    apply_texture_transform(extensions, s);
    return s;
  }
};

glm::vec4 vec4_of(const std::vector<double>& v, glm::vec4 fallback) {
  if (v.size() < 4) return fallback;
  glm::vec4 r{float(v[0]), float(v[1]), float(v[2]), float(v[3])};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(r[i])) return fallback;
  }
  return r;
}

float finite_or(double v, float fallback) {
  return std::isfinite(v) ? float(v) : fallback;
}

Material material_of(const tg::Material& g, TextureCache& cache) {
  Material m;
  m.name = g.name;
  PbrMaterial p;
  const tg::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
  p.base_color = glm::clamp(vec4_of(pbr.baseColorFactor, glm::vec4(1.0f)), 0.0f, 1.0f);
  p.base_color_map = cache.slot(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                pbr.baseColorTexture.extensions);
  p.metallic = std::clamp(finite_or(pbr.metallicFactor, 1.0f), 0.0f, 1.0f);
  p.roughness = std::clamp(finite_or(pbr.roughnessFactor, 1.0f), 0.0f, 1.0f);
  p.metallic_roughness_map =
      cache.slot(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                 pbr.metallicRoughnessTexture.extensions);
  p.normal_map =
      cache.slot(g.normalTexture.index, g.normalTexture.texCoord, g.normalTexture.extensions);
  p.normal_scale = finite_or(g.normalTexture.scale, 1.0f);
  p.occlusion_map = cache.slot(g.occlusionTexture.index, g.occlusionTexture.texCoord,
                               g.occlusionTexture.extensions);
  p.occlusion_strength = std::clamp(finite_or(g.occlusionTexture.strength, 1.0f), 0.0f, 1.0f);
  glm::vec4 e = vec4_of({g.emissiveFactor.size() >= 3 ? g.emissiveFactor[0] : 0.0,
                         g.emissiveFactor.size() >= 3 ? g.emissiveFactor[1] : 0.0,
                         g.emissiveFactor.size() >= 3 ? g.emissiveFactor[2] : 0.0, 0.0},
                        glm::vec4(0.0f));
  float strength = 1.0f;
  if (auto it = g.extensions.find("KHR_materials_emissive_strength"); it != g.extensions.end()) {
    strength = std::clamp(float(number(it->second, "emissiveStrength", 1.0)), 0.0f, 1.0e4f);
  }
  p.emissive = glm::clamp(glm::vec3(e), 0.0f, 1.0f) * strength;
  p.emissive_map =
      cache.slot(g.emissiveTexture.index, g.emissiveTexture.texCoord, g.emissiveTexture.extensions);
  p.alpha_mode = g.alphaMode == "MASK"    ? AlphaMode::kMask
                 : g.alphaMode == "BLEND" ? AlphaMode::kBlend
                                          : AlphaMode::kOpaque;
  p.alpha_cutoff = std::max(finite_or(g.alphaCutoff, 0.5f), 0.0f);
  p.double_sided = g.doubleSided;
  m.diffuse = glm::vec3(p.base_color);
  m.diffuse_map = p.base_color_map.texture;
  m.pbr = p;
  return m;
}

// ---- Geometry -------------------------------------------------------------------------------

// One primitive in its own (object) space, before the node's transform.
struct Piece {
  std::vector<glm::vec4> positions, normals, tangents, uvs, uvs1, colors;
  std::vector<uint32_t> triangles;  // three per triangle
  std::vector<uint32_t> lines;      // two per segment (LINES, LINE_STRIP, LINE_LOOP)
  std::vector<uint32_t> points;     // one per point (POINTS)
};

Status check_finite(const std::vector<glm::vec4>& values, const std::string& what) {
  for (const glm::vec4& v : values) {
    if (!(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w))) {
      return fail(what, "holds a value that is not a finite number");
    }
  }
  return {};
}

int attribute(const tg::Primitive& p, const char* name) {
  auto it = p.attributes.find(name);
  return it == p.attributes.end() ? -1 : it->second;
}

// The triangle list of a primitive's mode (triangles, strip, fan).
void triangulate(int mode, const std::vector<uint32_t>& in, std::vector<uint32_t>& out) {
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    out.assign(in.begin(), in.begin() + ptrdiff_t(in.size() / 3 * 3));
    return;
  }
  out.clear();
  for (size_t i = 2; i < in.size(); ++i) {
    if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
      out.insert(out.end(), {in[0], in[i - 1], in[i]});
    } else if (i % 2 == 0) {  // strip: every other triangle reversed to keep the winding
      out.insert(out.end(), {in[i - 2], in[i - 1], in[i]});
    } else {
      out.insert(out.end(), {in[i - 1], in[i - 2], in[i]});
    }
  }
}

Status read_piece(const tg::Model& m, const tg::Primitive& p, const std::string& what, Piece& out) {
  int position = attribute(p, "POSITION");
  if (Status s = read_floats(m, position, {3}, 3, glm::vec4(0, 0, 0, 1), out.positions); !s.ok()) {
    return fail(what, position < 0 ? "has no POSITION" : s.message());
  }
  if (Status s = check_finite(out.positions, what + ": POSITION"); !s.ok()) return s;
  size_t count = out.positions.size();
  struct Optional {
    const char* name;
    std::vector<int> types;
    glm::vec4 fill;
    std::vector<glm::vec4>* out;
  };
  for (const Optional& o : {Optional{"NORMAL", {3}, glm::vec4(0.0f), &out.normals},
                            Optional{"TANGENT", {4}, glm::vec4(1, 0, 0, 1), &out.tangents},
                            Optional{"TEXCOORD_0", {2}, glm::vec4(0.0f), &out.uvs},
                            Optional{"TEXCOORD_1", {2}, glm::vec4(0.0f), &out.uvs1},
                            Optional{"COLOR_0", {3, 4}, glm::vec4(1.0f), &out.colors}}) {
    int index = attribute(p, o.name);
    if (index < 0) continue;
    if (Status s = read_floats(m, index, o.types, 4, o.fill, *o.out); !s.ok()) {
      return fail(what, s.message());
    }
    if (o.out->size() != count) {
      return fail(what, std::string(o.name) + " has " + n(o.out->size()) + " elements, POSITION " +
                            n(count));
    }
    if (Status s = check_finite(*o.out, what + ": " + o.name); !s.ok()) return s;
  }
  std::vector<uint32_t> indices;
  if (p.indices >= 0) {
    if (Status s = read_indices(m, p.indices, indices); !s.ok()) return fail(what, s.message());
    for (uint32_t i : indices) {
      if (i >= count) {
        return fail(what, "index " + n(i) + " is past the vertex count " + n(count) +
                              " (accessor " + std::to_string(p.indices) + ")");
      }
    }
  } else {
    indices.resize(count);
    for (size_t i = 0; i < count; ++i) indices[i] = uint32_t(i);
  }
  const int mode = p.mode == -1 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode == TINYGLTF_MODE_POINTS) {
    out.points = std::move(indices);
  } else if (mode == TINYGLTF_MODE_LINE) {
    out.lines.assign(indices.begin(), indices.begin() + ptrdiff_t(indices.size() / 2 * 2));
  } else if (mode == TINYGLTF_MODE_LINE_STRIP || mode == TINYGLTF_MODE_LINE_LOOP) {
    for (size_t i = 1; i < indices.size(); ++i) {
      out.lines.insert(out.lines.end(), {indices[i - 1], indices[i]});
    }
    if (mode == TINYGLTF_MODE_LINE_LOOP && indices.size() > 2) {
      out.lines.insert(out.lines.end(), {indices.back(), indices.front()});
    }
  } else {
    triangulate(mode, indices, out.triangles);
  }
  return {};
}

// Flat normals where the file gives none (glTF's rule): every triangle gets its own corners.
void make_flat(Piece& piece) {
  Piece flat;
  auto copy = [&](const std::vector<glm::vec4>& from, std::vector<glm::vec4>& to, uint32_t i) {
    if (!from.empty()) to.push_back(from[i]);
  };
  for (size_t t = 0; t + 2 < piece.triangles.size(); t += 3) {
    glm::vec3 a(piece.positions[piece.triangles[t]]), b(piece.positions[piece.triangles[t + 1]]),
        c(piece.positions[piece.triangles[t + 2]]);
    glm::vec3 normal = glm::cross(b - a, c - a);
    float length = glm::length(normal);
    normal = length > 0.0f && std::isfinite(length) ? normal / length : glm::vec3(0, 0, 1);
    for (int k = 0; k < 3; ++k) {
      uint32_t i = piece.triangles[t + size_t(k)];
      flat.triangles.push_back(uint32_t(flat.positions.size()));
      flat.positions.push_back(piece.positions[i]);
      flat.normals.push_back(glm::vec4(normal, 0.0f));
      copy(piece.tangents, flat.tangents, i);
      copy(piece.uvs, flat.uvs, i);
      copy(piece.uvs1, flat.uvs1, i);
      copy(piece.colors, flat.colors, i);
    }
  }
  piece = std::move(flat);
}

// Tangents computed by compute_tangents on the piece alone (its own normals and uvs).
void add_tangents(Piece& piece) {
  Mesh scratch;
  for (size_t i = 0; i < piece.positions.size(); ++i) {
    scratch.positions.push_back(glm::vec3(piece.positions[i]));
    scratch.normals.push_back(glm::vec3(piece.normals[i]));
    scratch.uvs.push_back(piece.uvs.empty() ? glm::vec2(0.0f)
                                            : glm::vec2(piece.uvs[i].x, 1.0f - piece.uvs[i].y));
  }
  scratch.indices = piece.triangles;
  compute_tangents(scratch);
  piece.tangents.resize(piece.positions.size());
  for (size_t i = 0; i < piece.positions.size(); ++i) piece.tangents[i] = scratch.tangents[i];
}

// What the flattened mesh is collecting.
struct Builder {
  Mesh mesh;
  bool any_tangents = false, any_uvs1 = false, any_colors = false;
  int skipped_primitives = 0;  // primitives of no glTF mode, not drawn (a warning names each)
  std::vector<glm::vec4> tangents, colors;
  std::vector<glm::vec2> uvs1;
};

bool needs_tangents(const Mesh& mesh, int material) {
  if (material < 0 || size_t(material) >= mesh.materials.size()) return false;
  const std::optional<PbrMaterial>& p = mesh.materials[size_t(material)].pbr;
  return p && p->normal_map;
}

// Appends a piece transformed by `world` as a submesh of `material`.
Status append(Builder& b, Piece& piece, const glm::mat4& world, int material,
              const std::string& what) {
  if (piece.triangles.empty() && piece.lines.empty() && piece.points.empty()) return {};
  size_t base = b.mesh.positions.size();
  // Checked before flat normals multiply the vertices (three per triangle) as well as after.
  size_t added = piece.normals.empty() && !piece.triangles.empty() ? piece.triangles.size()
                                                                   : piece.positions.size();
  if (base + added > size_t(kMaxGltfVertices) ||
      b.mesh.indices.size() / 3 + piece.triangles.size() / 3 > size_t(kMaxGltfTriangles)) {
    return fail(what, "the scene has more than " + n(kMaxGltfVertices) + " vertices or " +
                          n(kMaxGltfTriangles) + " triangles once its nodes are flattened");
  }
  if (piece.normals.empty() && !piece.triangles.empty()) make_flat(piece);
  if (piece.normals.empty()) piece.normals.assign(piece.positions.size(), glm::vec4(0, 0, 1, 0));
  if (piece.tangents.empty() && needs_tangents(b.mesh, material)) add_tangents(piece);
  glm::mat3 linear(world);
  glm::mat3 normal_matrix = glm::transpose(glm::inverse(linear));
  float det = glm::determinant(linear);
  float handedness = det < 0.0f ? -1.0f : 1.0f;
  for (size_t i = 0; i < piece.positions.size(); ++i) {
    glm::vec3 p = glm::vec3(world * glm::vec4(glm::vec3(piece.positions[i]), 1.0f));
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
      return fail(what, "a position is not finite once transformed by its node");
    }
    b.mesh.positions.push_back(p);
    glm::vec3 nrm = normal_matrix * glm::vec3(piece.normals[i]);
    float len = glm::length(nrm);
    b.mesh.normals.push_back(len > 0.0f && std::isfinite(len) ? nrm / len : glm::vec3(0, 0, 1));
    glm::vec2 uv = piece.uvs.empty() ? glm::vec2(0.0f) : glm::vec2(piece.uvs[i]);
    b.mesh.uvs.push_back({uv.x, 1.0f - uv.y});  // glTF's v runs down the image
    if (!piece.tangents.empty()) {
      b.any_tangents = true;
      glm::vec3 t = linear * glm::vec3(piece.tangents[i]);
      float tl = glm::length(t);
      t = tl > 0.0f && std::isfinite(tl) ? t / tl : glm::vec3(1, 0, 0);
      // glTF's bitangent, w * cross(normal, tangent), points up the image as the normal map's
      // green channel does (MikkTSpace on uvs with v up, as exporters compute it): softrast's
      // convention already. A mirroring transform reverses the cross product: w flips with it.
      float w = piece.tangents[i].w < 0.0f ? -1.0f : 1.0f;
      b.tangents.resize(base + i, glm::vec4(1, 0, 0, 1));
      b.tangents.push_back(glm::vec4(t, w * handedness));
    }
    if (!piece.uvs1.empty()) {
      b.any_uvs1 = true;
      b.uvs1.resize(base + i, glm::vec2(0.0f));
      b.uvs1.push_back({piece.uvs1[i].x, 1.0f - piece.uvs1[i].y});
    }
    if (!piece.colors.empty()) {
      b.any_colors = true;
      b.colors.resize(base + i, glm::vec4(1.0f));
      b.colors.push_back(piece.colors[i]);
    }
  }
  if (!piece.triangles.empty()) {
    SubMesh sub{uint32_t(b.mesh.indices.size()), uint32_t(piece.triangles.size()), material};
    for (size_t t = 0; t < piece.triangles.size(); t += 3) {
      uint32_t i0 = uint32_t(base) + piece.triangles[t],
               i1 = uint32_t(base) + piece.triangles[t + 1],
               i2 = uint32_t(base) + piece.triangles[t + 2];
      if (det < 0.0f) std::swap(i1, i2);  // a mirroring node turns its faces clockwise: undo it
      b.mesh.indices.insert(b.mesh.indices.end(), {i0, i1, i2});
    }
    b.mesh.submeshes.push_back(sub);
  }
  for (auto [from, to, runs] :
       {std::tuple{&piece.lines, &b.mesh.line_indices, &b.mesh.line_submeshes},
        std::tuple{&piece.points, &b.mesh.point_indices, &b.mesh.point_submeshes}}) {
    if (from->empty()) continue;
    runs->push_back({uint32_t(to->size()), uint32_t(from->size()), material});
    for (uint32_t i : *from) to->push_back(uint32_t(base) + i);
  }
  return {};
}

glm::mat4 local_transform(const tg::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m(1.0f);
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) m[c][r] = float(node.matrix[size_t(c * 4 + r)]);
    }
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3) {
    m[3] = glm::vec4(float(node.translation[0]), float(node.translation[1]),
                     float(node.translation[2]), 1.0f);
  }
  if (node.rotation.size() == 4) {
    glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                float(node.rotation[2]));  // glTF stores x, y, z, w
    float len = glm::length(q);
    if (len > 0.0f && std::isfinite(len)) m = m * glm::mat4_cast(q / len);
  }
  if (node.scale.size() == 3) {
    m = m * glm::mat4(glm::vec4(float(node.scale[0]), 0, 0, 0),
                      glm::vec4(0, float(node.scale[1]), 0, 0),
                      glm::vec4(0, 0, float(node.scale[2]), 0), glm::vec4(0, 0, 0, 1));
  }
  return m;
}

struct Flattener {
  const tg::Model& model;
  Builder& builder;
  int default_material;  // for primitives without one (glTF's default material), -1 until needed
  std::vector<bool> visited;
  // Primitives that gave no triangle: not read again for the next node drawing their mesh.
  std::set<std::pair<int, size_t>> empty;

  int material_for(int index) {
    if (index >= 0 && size_t(index) < model.materials.size()) return index;
    if (default_material < 0) {
      Material m;
      m.name = "(glTF default material)";
      m.diffuse = glm::vec3(1.0f);
      m.pbr = PbrMaterial{};
      default_material = int(builder.mesh.materials.size());
      builder.mesh.materials.push_back(m);
    }
    return default_material;
  }

  Status add_mesh(int index, const glm::mat4& world) {
    std::string what = "mesh " + std::to_string(index);
    if (index < 0 || size_t(index) >= model.meshes.size()) return fail(what, "does not exist");
    const tg::Mesh& mesh = model.meshes[size_t(index)];
    for (size_t k = 0; k < mesh.primitives.size(); ++k) {
      const tg::Primitive& p = mesh.primitives[k];
      std::string pwhat = what + " primitive " + std::to_string(k);
      if (p.mode < -1 || p.mode > TINYGLTF_MODE_TRIANGLE_FAN) {
        builder.mesh.warnings.push_back(pwhat + ": mode " + std::to_string(p.mode) +
                                        " is not a glTF primitive mode; not drawn");
        ++builder.skipped_primitives;
        continue;
      }
      if (empty.count({index, k})) continue;
      Piece piece;
      if (Status s = read_piece(model, p, pwhat, piece); !s.ok()) return s;
      if (piece.triangles.empty() && piece.lines.empty() && piece.points.empty()) {
        empty.insert({index, k});
      }
      if (Status s = append(builder, piece, world, material_for(p.material), pwhat); !s.ok())
        return s;
    }
    return {};
  }

  // Depth-first with an explicit stack: a deep hierarchy cannot overflow the call stack, and a
  // node reached twice (a cycle, or a node with two parents) is an error.
  Status walk(int root) {
    std::vector<std::pair<int, glm::mat4>> stack{{root, glm::mat4(1.0f)}};
    while (!stack.empty()) {
      auto [index, parent] = stack.back();
      stack.pop_back();
      std::string what = "node " + std::to_string(index);
      if (index < 0 || size_t(index) >= model.nodes.size()) return fail(what, "does not exist");
      if (visited[size_t(index)]) {
        return fail(what, "is reached twice (the nodes must form trees)");
      }
      visited[size_t(index)] = true;
      const tg::Node& node = model.nodes[size_t(index)];
      glm::mat4 world = parent * local_transform(node);
      if (node.mesh >= 0) {
        if (Status s = add_mesh(node.mesh, world); !s.ok()) return s;
      }
      for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) {
        stack.push_back({*it, world});
      }
    }
    return {};
  }
};

// The root nodes to draw: the default scene's (scene 0 without one), or with no scenes every
// node that is no other node's child.
std::vector<int> roots(const tg::Model& m) {
  if (!m.scenes.empty()) {
    int s = m.defaultScene >= 0 && size_t(m.defaultScene) < m.scenes.size() ? m.defaultScene : 0;
    return m.scenes[size_t(s)].nodes;
  }
  std::vector<bool> child(m.nodes.size(), false);
  for (const tg::Node& node : m.nodes) {
    for (int c : node.children) {
      if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = true;
    }
  }
  std::vector<int> r;
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    if (!child[i]) r.push_back(int(i));
  }
  return r;
}

}  // namespace

Status gltf_read_every_accessor(const GltfDocument& doc) {
  for (size_t i = 0; i < doc.model.accessors.size(); ++i) {
    std::vector<glm::vec4> values;
    if (Status s = read_floats(doc.model, int(i), {1, 2, 3, 4}, 4, glm::vec4(0.0f), values);
        !s.ok()) {
      return s;
    }
  }
  return {};
}

Result<Mesh> gltf_to_mesh(GltfDocument& doc, const std::string& name, const std::string& base_dir) {
  const tg::Model& m = doc.model;
  Builder b;
  TextureCache cache{&m, &doc, name, base_dir, {}, &b.mesh.warnings};
  for (const tg::Material& g : m.materials) b.mesh.materials.push_back(material_of(g, cache));
  Flattener f{m, b, -1, std::vector<bool>(m.nodes.size(), false), {}};
  Status status;
  if (m.nodes.empty()) {  // meshes without nodes: each drawn once, untransformed
    for (size_t i = 0; i < m.meshes.size() && status.ok(); ++i)
      status = f.add_mesh(int(i), glm::mat4(1.0f));
  } else {
    for (int root : roots(m)) {
      status = f.walk(root);
      if (!status.ok()) break;
    }
  }
  if (!status.ok()) return fail(name, status.message());
  if (b.mesh.indices.empty() && b.mesh.line_indices.empty() && b.mesh.point_indices.empty()) {
    if (b.skipped_primitives > 0) {
      return fail(name, "nothing to draw: its " + std::to_string(b.skipped_primitives) +
                            " primitive" + (b.skipped_primitives == 1 ? " has" : "s have") +
                            " no glTF primitive mode");
    }
    return fail(name, "no triangles, lines or points to draw");
  }
  if (b.any_tangents) {
    b.tangents.resize(b.mesh.positions.size(), glm::vec4(1, 0, 0, 1));
    b.mesh.tangents = std::move(b.tangents);
  }
  if (b.any_uvs1) {
    b.uvs1.resize(b.mesh.positions.size(), glm::vec2(0.0f));
    b.mesh.uvs1 = std::move(b.uvs1);
  }
  if (b.any_colors) {
    b.colors.resize(b.mesh.positions.size(), glm::vec4(1.0f));
    b.mesh.colors = std::move(b.colors);
  }
  for (std::string& w : doc.warnings) b.mesh.warnings.push_back(std::move(w));
  return std::move(b.mesh);
}

}  // namespace detail

Result<Mesh> load_gltf(const std::string& path) {
  std::vector<char> bytes;
  if (Status s = detail::read_whole_file(path, kMaxGltfFileBytes, "glTF files", bytes); !s.ok()) {
    return s;
  }
  std::string dir = std::filesystem::path(path).parent_path().string();
  if (dir.empty()) dir = ".";
  Result<detail::GltfDocument> doc = detail::read_gltf_document(
      reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), path, dir);
  if (!doc) return doc.status();
  return detail::gltf_to_mesh(*doc, path, dir);
}

}  // namespace softrast
