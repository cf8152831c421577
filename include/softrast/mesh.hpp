// softrast/mesh.hpp: indexed triangle meshes with materials, and the OBJ/MTL loader.
// Positions are in model (here: world) space; the renderer applies the camera.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "softrast/pbr_material.hpp"
#include "softrast/status.hpp"
#include "softrast/texture.hpp"

namespace softrast {

// How a normal map's texels (rgb * 2 - 1 = xyz) are meant: in the surface's tangent frame
// (MikkTSpace: x along the tangent, y along the bitangent, z the vertex normal; needs
// Mesh::tangents), or in the model's own coordinates (object space).
enum class NormalSpace { kTangent, kObject };

// A surface's look for the built-in lit shaders (Blinn-Phong): colour = diffuse * (ambient +
// diffuse light) + specular * highlight^shininess. The defaults are SCENES.md's (albedo A,
// specular 0.4, shininess 32), so a model that says nothing looks as it always has.
struct Material {
  std::string name;
  glm::vec3 diffuse{0.9f, 0.6f, 0.3f};  // Kd; the default is SCENES.md's albedo A
  glm::vec3 specular{0.4f};             // Ks, times the light intensity
  float shininess = 32.0f;              // Ns, the Blinn-Phong exponent, in [0, 1000]
  float opacity = 1.0f;                 // d (or 1 - Tr), multiplies the output alpha
  // Maps, each null when absent. Colour maps (diffuse) are ColorSpace::kSrgb textures.
  std::shared_ptr<const Texture> diffuse_map;   // map_Kd, or <model>_diffuse.tga: rgb and alpha
  std::shared_ptr<const Texture> specular_map;  // map_Ks, or <model>_spec.tga: rgb multiplies Ks
  std::shared_ptr<const Texture> normal_map;    // norm, map_Bump/bump, <model>_nm[_tangent].tga
  NormalSpace normal_space = NormalSpace::kTangent;
  float normal_scale = 1.0f;                 // -bm: scales the map's x and y (its slope)
  std::shared_ptr<const Texture> alpha_map;  // map_d: its red channel multiplies the alpha
  // Where the maps lie on the surface, from the maps' MTL options: -s u v (scale) and -o u v
  // (origin offset) read every map at uv * uv_scale + uv_offset; -clamp on clamps them to the
  // edge instead of repeating. One placement for all the maps of a material (the options of
  // map_Kd, or of the first map that has any); a --texture given instead is placed the same way.
  glm::vec2 uv_scale{1.0f};
  glm::vec2 uv_offset{0.0f};
  bool clamp_maps = false;
  // glTF's metallic-roughness material (set by the glTF loader, which also sets diffuse and
  // diffuse_map to the base colour for the other shaders); ShaderKind::kPbr draws a material
  // without one as a dielectric of its diffuse colour.
  std::optional<PbrMaterial> pbr;
};

// A run of indices drawn with one material.
struct SubMesh {
  uint32_t first_index = 0;  // into Mesh::indices (line_indices, point_indices for those runs)
  uint32_t index_count = 0;  // a multiple of 3 (of 2 for lines)
  int material = -1;         // into Mesh::materials, or -1 for the default material
};

// Vertices are de-duplicated (one per distinct position/normal/uv triple); every vertex has a
// normal and a uv (missing normals are area-weighted smooth normals, missing uvs are (0, 0)).
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  // Optional per-vertex data: empty, or one per position.
  // Tangents for tangent-space normal maps, MikkTSpace's convention: xyz the tangent (the
  // direction of increasing u, orthogonal to the normal), w = +1 or -1 the handedness, so that
  // the bitangent (increasing v) is w * cross(normal, tangent). compute_tangents fills them.
  std::vector<glm::vec4> tangents;
  std::vector<glm::vec4>
      colors;  // RGBA vertex colours: glTF COLOR_0 (linear), OBJ and PLY (as stored)
  std::vector<glm::vec2> uvs1;     // a second texture coordinate set (glTF TEXCOORD_1)
  std::vector<uint32_t> indices;   // three per triangle
  std::vector<SubMesh> submeshes;  // cover `indices`; empty means one run with material -1
  // Lines and points of the file (OBJ's l and p; glTF's LINES, LINE_LOOP, LINE_STRIP and POINTS):
  // two indices per segment and one per point, into the same vertices, in runs of one material as
  // `submeshes` (empty: one run with material -1). render_mesh draws them after the triangles,
  // one pixel wide, unlit in the material's diffuse colour (or the vertex colours), depth-tested.
  std::vector<uint32_t> line_indices;
  std::vector<SubMesh> line_submeshes;
  std::vector<uint32_t> point_indices;
  std::vector<SubMesh> point_submeshes;
  std::vector<Material> materials;
  // Problems the loader worked around, one line each ("model.obj:1: ..."): a missing MTL library,
  // a missing or unreadable map_Kd texture. The mesh is usable; a program shows these to the user.
  std::vector<std::string> warnings;

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
};

// Largest OBJ file load_obj reads: 2 GiB, some 250 million triangles written tersely, whose mesh
// (12 bytes of indices per triangle) is already more than most machines will render.
inline constexpr int64_t kMaxObjFileBytes = int64_t(2) << 30;

// Largest MTL file load_obj reads: 64 MiB, far beyond any real material library.
inline constexpr int64_t kMaxMtlFileBytes = int64_t(64) << 20;

// Loads a Wavefront OBJ (convex polygons fanned, concave ones cut by ear clipping) with its MTL
// libraries (Kd, Ks, Ns, d or Tr, illum, map_Kd, map_Ks, map_d, and norm, map_Bump or bump with
// -bm as tangent-space normal maps; a greyscale bump map is a height map, turned into a normal
// map); v, vt, vn, f, usemtl and mtllib are read, other statements skipped. Texture paths are
// relative to the MTL file, MTL paths to the OBJ, and found as find_referenced_file finds them
// (Windows separators, case). An OBJ with no materials at all takes the maps of the tutorial
// models' convention beside it, when they exist: <model>_diffuse.tga, <model>_spec.tga, and
// <model>_nm_tangent.tga (tangent space) or else <model>_nm.tga (object space), as one material
// named after the model. A material with a tangent-space normal map gets Mesh::tangents. A missing
// MTL leaves its materials undefined (their faces get the default material) and a missing or
// unreadable map_Kd leaves its material untextured; both add a line to Mesh::warnings:
//   "model.obj:1: material library 'model.mtl' not found; its materials get the default colour"
//   "model.obj: material 'skin': map_Kd: skin.png: cannot open: No such file or directory; drawn
//    without this texture"  (the second part is load_image's message)
// Errors name the file and, where there is one, the line
// ("model.obj:12: face index 99999999999999999999 is out of range (1..3 or -3..-1)"): missing or
// unreadable file, a folder, more than kMaxObjFileBytes (kMaxMtlFileBytes for an MTL; a pipe or
// device is cut off there), a NUL byte (not a text file), a line over 1 MiB, a number that is not
// one or not finite as a float, a face with fewer than 3 corners or an index that is zero, out
// of range or overflowing, no faces, an MTL file that exists but cannot be read or is malformed.
Result<Mesh> load_obj(const std::string& path);

// The file an OBJ or MTL names (an MTL library or a map) relative to `folder`, as load_obj finds
// it: the path as written; else with backslashes read as folder separators (files written on
// Windows); else its folders and name matched without regard to case; else, where its folders do
// not exist here (an absolute path from the author's machine), the file of that name in `folder`
// (load_obj then adds a warning naming the file it took). nullopt when none exists.
std::optional<std::string> find_referenced_file(const std::string& folder, const std::string& name);

// Loads a PLY file: ASCII, binary little or big endian. The vertex element's x, y, z, and when
// present nx, ny, nz and u, v (or s, t, texture_u, texture_v, texture_s, texture_t), and red,
// green, blue (alpha) as Mesh::colors (integers over their type's largest value, 255 for uchar;
// floats as they are; clamped to [0, 1]); other properties are read and dropped. Faces are the face
// element's vertex_indices (or vertex_index) list of any integer types (a convex face fanned, a
// concave one cut by ear clipping). Without normals, smooth normals are computed. Errors name the
// file and the line (ASCII) or the element and byte (binary): a bad header, counts that need more
// bytes than the file has (checked before allocating), lists over 65536 items, a number that does
// not fit its type, a vertex index out of range, no vertices. Vertices without faces are a point
// cloud: every vertex one of Mesh::point_indices.
Result<Mesh> load_ply(const std::string& path);

// Loads an STL file, binary (84 + 50 * count bytes; bytes after the triangles are a warning) or
// ASCII (solid ... endsolid, keywords in any case). Every triangle gets three vertices of its
// own with the facet normal (the triangle's own normal where the facet normal is zero or not
// finite), uv (0, 0). Errors: fewer bytes than the count needs (truncated), a keyword out of
// place or missing (the file and line), a number that is not one or not finite, no triangles.
Result<Mesh> load_stl(const std::string& path);

// Largest glTF or GLB file, and largest external buffer, load_gltf reads: 1 GiB.
inline constexpr int64_t kMaxGltfFileBytes = int64_t(1) << 30;
// Largest flattened glTF mesh: 2^24 vertices and 2^25 triangles (some 1.6 GiB of mesh), checked
// before each primitive is added (a mesh instanced by many nodes counts once per node).
inline constexpr int64_t kMaxGltfVertices = int64_t(1) << 24;
inline constexpr int64_t kMaxGltfTriangles = int64_t(1) << 25;

// Loads a glTF 2.0 scene (.gltf with external or data-URI buffers, or .glb) as one mesh: the
// default scene's node hierarchy flattened into world space (positions, normals, tangents with
// their handedness kept under mirroring transforms, the winding of mirrored nodes reversed), one
// SubMesh per primitive instance, one Material (with `pbr` set) per glTF material. Triangles,
// strips and fans are drawn; points and lines are skipped with a warning. Missing normals are
// flat; missing tangents are computed where a material has a normal map. Extensions:
// KHR_texture_transform, KHR_materials_emissive_strength, KHR_mesh_quantization; any other in
// extensionsRequired is an error. Images are PNG, JPEG or TGA through load_image's decoders; a
// missing or unreadable image is a warning. Errors are one line naming the file and the object
// ("scene.gltf: accessor 3: 24 elements of 12 bytes need 288 bytes from byte 0, but bufferView 1
// has 200"): invalid JSON or GLB framing, a buffer file missing or of the wrong size, a data URI
// that is not base64, an index out of range, accessors (or their sparse indices and values) past
// their bufferView, sparse indices out of range or not increasing, non-finite positions, counts
// over kMaxGltfVertices / kMaxGltfTriangles, no triangles.
Result<Mesh> load_gltf(const std::string& path);

// Loads a model, telling the format by content: glTF by "{ ... "asset"" or GLB's magic, PLY by
// its "ply" line, binary STL by its size, ASCII STL by "solid", OBJ otherwise. A file that looks
// like something else is refused with what it looks like: "x.png: this is a PNG image, not a
// model (softrast reads OBJ, PLY, STL and glTF)" (PNG, JPEG, GIF, BMP, TGA images, ZIP, PDF,
// gzip, ELF, FBX). A .stl or .ply
// name whose content is neither goes to that format's loader, which says why it is not one.
// Pipes and devices (which can be read only once) are read as OBJ.
Result<Mesh> load_model(const std::string& path);

// Fills `mesh.normals` with area-weighted smooth normals per position (used when the file has
// none). Degenerate neighbourhoods get (0, 0, 1).
void compute_smooth_normals(Mesh& mesh);

// Fills `mesh.tangents` from the positions, normals and uvs (MikkTSpace's convention, see Mesh):
// each triangle's tangent and bitangent from its uv gradient, summed at its corners weighted by
// the corner angle, then made orthogonal to the vertex normal (Gram-Schmidt); w is the sign of
// the summed bitangent against cross(normal, tangent). A vertex whose triangles have no usable
// uv gradient gets a tangent orthogonal to its normal, w = +1. Needs normals and uvs.
void compute_tangents(Mesh& mesh);

}  // namespace softrast
