// apps/softrast/info.cpp: the info command. Geometry comes from load_obj (what the renderer
// draws); the files a model refers to come from a scan of its mtllib statements and of the MTL
// libraries' newmtl and map statements, so that a missing file is listed even when it stops the
// model from loading.

#include "info.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string_view>

#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "report.hpp"
#include "softrast/mesh.hpp"

namespace softrast::cli {
namespace {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

// A file named inside a model: an MTL library or a texture map.
struct Reference {
  std::string kind;  // "mtllib", "map_Kd", "bump", ...
  std::string path;  // as written
  fs::path resolved;
  bool found = false;
};

struct ScannedMaterial {
  std::string name;
  std::vector<Reference> maps;
};

// Statement counts and references, read from the text (whatever load_obj makes of it).
struct Scan {
  size_t positions = 0, texcoords = 0, normals = 0, faces = 0;
  std::vector<Reference> libraries;
  std::vector<ScannedMaterial> materials;
};

std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> words;
  size_t at = 0;
  while (true) {
    at = line.find_first_not_of(" \t\r", at);
    if (at == line.npos) break;
    size_t end = std::min(line.find_first_of(" \t\r", at), line.size());
    words.push_back(line.substr(at, end - at));
    at = end;
  }
  return words;
}

// Resolved as load_obj resolves it (find_referenced_file: Windows separators, case, a folder of
// the author's machine).
Reference reference(std::string kind, std::string_view path, const fs::path& folder) {
  Reference r{std::move(kind), std::string(path), folder / std::string(path), false};
  if (std::optional<std::string> found = find_referenced_file(folder.string(), r.path)) {
    r.resolved = *found;
  }
  std::error_code ec;
  r.found = fs::is_regular_file(r.resolved, ec);
  return r;
}

// Map statements: map_Kd, map_Bump, ... and the older bump, disp, decal, refl, norm. The file is
// the last word (options such as -s 1 1 1 come before it).
bool is_map(std::string_view keyword) {
  return keyword.rfind("map_", 0) == 0 || keyword == "bump" || keyword == "disp" ||
         keyword == "decal" || keyword == "refl" || keyword == "norm";
}

// The file a map statement names: what follows its options (-s 1 1 1, -clamp on, ...), spaces
// kept, as tinyobj (and so the render) reads it.
std::string map_file(const std::vector<std::string_view>& w) {
  auto number = [](std::string_view word) {
    double d = 0.0;
    auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), d);
    return ec == std::errc() && end == word.data() + word.size();
  };
  size_t i = 1;
  while (i < w.size() && w[i].size() > 1 && w[i][0] == '-') {
    std::string_view option = w[i++];
    if (option == "-o" || option == "-s" || option == "-t") {  // one to three numbers
      for (int k = 0; k < 3 && i < w.size() && number(w[i]); ++k) ++i;
    } else if (option == "-mm") {
      i += 2;
    } else {  // -blendu, -blendv, -boost, -cc, -clamp, -imfchan, -texres, -bm, -type: one word
      ++i;
    }
  }
  std::string file;
  for (; i < w.size(); ++i) file.append(file.empty() ? "" : " ").append(w[i]);
  return file;
}

void scan_library(const Reference& library, Scan& scan) {
  std::ifstream in(library.resolved);
  std::string line;
  fs::path folder = library.resolved.parent_path();
  while (std::getline(in, line)) {
    std::vector<std::string_view> w = words_of(line);
    if (w.size() >= 2 && w[0] == "newmtl") scan.materials.push_back({std::string(w[1]), {}});
    if (w.size() >= 2 && is_map(w[0]) && !scan.materials.empty()) {
      scan.materials.back().maps.push_back(reference(std::string(w[0]), map_file(w), folder));
    }
  }
}

Scan scan_model(const std::string& path) {
  Scan scan;
  std::ifstream in(path);
  std::string line;
  fs::path folder = fs::path(path).parent_path();
  while (std::getline(in, line)) {
    std::vector<std::string_view> w = words_of(line);
    if (w.empty()) continue;
    if (w[0] == "v") ++scan.positions;
    if (w[0] == "vt") ++scan.texcoords;
    if (w[0] == "vn") ++scan.normals;
    if (w[0] == "f") ++scan.faces;
    if (w[0] == "mtllib") {
      for (size_t i = 1; i < w.size(); ++i)
        scan.libraries.push_back(reference("mtllib", w[i], folder));
    }
  }
  for (const Reference& library : scan.libraries) {
    if (library.found) scan_library(library, scan);
  }
  return scan;
}

ojson vec3_json(glm::vec3 v) {
  return ojson::array({rounded(v.x, 6), rounded(v.y, 6), rounded(v.z, 6)});
}

ojson reference_json(const Reference& r) {
  return {
      {"kind", r.kind}, {"path", r.path}, {"resolved", r.resolved.string()}, {"found", r.found}};
}

const Material* material_named(const Mesh* mesh, const std::string& name) {
  if (!mesh) return nullptr;
  for (const Material& m : mesh->materials) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

ojson materials_json(const Scan& scan, const Mesh* mesh) {
  ojson materials = ojson::array();
  for (const ScannedMaterial& s : scan.materials) {
    ojson m = {{"name", s.name}};
    if (const Material* loaded = material_named(mesh, s.name)) {
      m["diffuse"] = vec3_json(loaded->diffuse);
      m["diffuse_map_loaded"] = loaded->diffuse_map != nullptr;
      // Where the maps lie (MTL -s, -o, -clamp), as the renderer places every map.
      m["uv_scale"] =
          ojson::array({rounded(loaded->uv_scale.x, 6), rounded(loaded->uv_scale.y, 6)});
      m["uv_offset"] =
          ojson::array({rounded(loaded->uv_offset.x, 6), rounded(loaded->uv_offset.y, 6)});
      m["clamp_maps"] = loaded->clamp_maps;
    }
    ojson maps = ojson::array();
    for (const Reference& r : s.maps) maps.push_back(reference_json(r));
    m["maps"] = std::move(maps);
    materials.push_back(std::move(m));
  }
  return materials;
}

ojson geometry_json(const Mesh& mesh) {
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi = -lo;
  for (glm::vec3 p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  ojson submeshes = ojson::array();
  for (const SubMesh& s : mesh.submeshes) {
    bool named = s.material >= 0 && size_t(s.material) < mesh.materials.size();
    submeshes.push_back(
        {{"material", named ? ojson(mesh.materials[size_t(s.material)].name) : ojson(nullptr)},
         {"triangles", s.index_count / 3}});
  }
  if (mesh.submeshes.empty()) {
    submeshes.push_back({{"material", nullptr}, {"triangles", mesh.triangle_count()}});
  }
  return {{"triangles", mesh.triangle_count()},
          {"line_segments", mesh.line_indices.size() / 2},
          {"points", mesh.point_indices.size()},
          {"vertices", mesh.vertex_count()},
          {"bounds",
           {{"min", vec3_json(lo)},
            {"max", vec3_json(hi)},
            {"size", vec3_json(hi - lo)},
            {"center", vec3_json((lo + hi) * 0.5f)}}},
          {"submeshes", std::move(submeshes)}};
}

// Everything known about one model; "error" when it does not load.
ojson describe(const std::string& path) {
  ojson info = {{"model", path}};
  Result<Mesh> mesh = load_model(path);
  if (!mesh) info["error"] = mesh.status().message();
  if (mesh && !mesh->warnings.empty()) info["warnings"] = mesh->warnings;  // e.g. a missing map
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return info;
  Scan scan = scan_model(path);
  if (mesh) info.update(geometry_json(*mesh));
  // A model that loaded with no OBJ statement in it is a PLY, STL or glTF file: its statement
  // counts and MTL libraries mean nothing, and its materials come from the loaded mesh.
  bool obj = !mesh || scan.positions > 0 || scan.faces > 0 || !scan.libraries.empty();
  if (!obj) {
    ojson materials = ojson::array();
    for (const Material& m : mesh->materials) {
      materials.push_back({{"name", m.name},
                           {"diffuse", vec3_json(m.diffuse)},
                           {"diffuse_map_loaded", m.diffuse_map != nullptr},
                           {"pbr", m.pbr.has_value()},
                           {"maps", ojson::array()}});
    }
    info["materials"] = std::move(materials);
    return info;
  }
  info["file"] = {{"positions", scan.positions},
                  {"texcoords", scan.texcoords},
                  {"normals", scan.normals},
                  {"faces", scan.faces}};
  ojson libraries = ojson::array();
  for (const Reference& r : scan.libraries) libraries.push_back(reference_json(r));
  info["libraries"] = std::move(libraries);
  info["materials"] = materials_json(scan, mesh ? &*mesh : nullptr);
  return info;
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

std::string triple(const ojson& v) {
  return number(v[0].get<double>()) + " " + number(v[1].get<double>()) + " " +
         number(v[2].get<double>());
}

std::string found_text(const ojson& r) {
  return r["path"].get<std::string>() + (r["found"].get<bool>() ? " (found)" : " (MISSING)");
}

void print_geometry(const ojson& info) {
  std::printf("  triangles  %s\n", info["triangles"].dump().c_str());
  if (info.value("line_segments", 0) > 0) {
    std::printf("  lines      %s segments\n", info["line_segments"].dump().c_str());
  }
  if (info.value("points", 0) > 0) std::printf("  points     %s\n", info["points"].dump().c_str());
  if (info.contains("file")) {  // an OBJ: what its statements count
    const ojson& f = info["file"];
    std::printf(
        "  vertices   %s (the file: %s positions, %s texture coordinates, %s normals, %s "
        "faces)\n",
        info["vertices"].dump().c_str(), f["positions"].dump().c_str(),
        f["texcoords"].dump().c_str(), f["normals"].dump().c_str(), f["faces"].dump().c_str());
  } else {
    std::printf("  vertices   %s\n", info["vertices"].dump().c_str());
  }
  const ojson& b = info["bounds"];
  std::printf("  bounds     min %s  max %s  size %s  center %s\n", triple(b["min"]).c_str(),
              triple(b["max"]).c_str(), triple(b["size"]).c_str(), triple(b["center"]).c_str());
  std::printf("  submeshes  %zu\n", info["submeshes"].size());
  for (const ojson& s : info["submeshes"]) {
    std::string name = s["material"].is_null() ? "(default material)"
                       : s["material"].get<std::string>().empty()
                           ? "(unnamed material)"
                           : s["material"].get<std::string>();
    std::printf("    %s: %s triangles\n", name.c_str(), s["triangles"].dump().c_str());
  }
}

void print_references(const ojson& info) {
  if (info.contains("libraries")) {
    for (const ojson& r : info["libraries"])
      std::printf("  mtllib     %s\n", found_text(r).c_str());
  }
  std::printf("  materials  %zu\n", info["materials"].size());
  for (const ojson& m : info["materials"]) {
    std::string kd = m.contains("diffuse") ? "  Kd " + triple(m["diffuse"]) : "";
    if (m.contains("pbr") && m["pbr"].get<bool>()) kd += "  (metallic-roughness)";
    if (m.contains("pbr") && m["diffuse_map_loaded"].get<bool>()) kd += "  base colour map";
    std::string name = m["name"].get<std::string>();
    std::printf("    %s%s\n", name.empty() ? "(unnamed)" : name.c_str(), kd.c_str());
    if (m.contains("uv_scale") &&
        (m["uv_scale"] != ojson::array({1, 1}) || m["uv_offset"] != ojson::array({0, 0}) ||
         m["clamp_maps"].get<bool>())) {
      auto pair = [](const ojson& v) {
        return number(v[0].get<double>()) + " " + number(v[1].get<double>());
      };
      std::printf("      maps placed at uv * (%s) + (%s)%s\n", pair(m["uv_scale"]).c_str(),
                  pair(m["uv_offset"]).c_str(),
                  m["clamp_maps"].get<bool>() ? ", clamped to the edge" : "");
    }
    for (const ojson& r : m["maps"]) {
      std::printf("      %s %s\n", r["kind"].get<std::string>().c_str(), found_text(r).c_str());
    }
  }
}

void print_text(const ojson& info) {
  std::printf("%s\n", info["model"].get<std::string>().c_str());
  if (info.contains("triangles")) print_geometry(info);
  if (info.contains("materials")) print_references(info);
}

}  // namespace

void define_info_flags(CLI::App& app, InfoArgs& a) {
  app.add_option("MODEL", a.models, "Model files: OBJ, PLY, STL or glTF")->required();
  app.add_flag("--json", a.json,
               "One JSON object per model and line: model, triangles, vertices, bounds (min, max, "
               "size, center), submeshes, and for OBJ files file (statement counts), libraries "
               "and materials with their maps (path, resolved, found); for PLY, STL and glTF the "
               "loaded materials (name, diffuse, pbr); or error");
  app.footer(
      "Vertices are the mesh's (one per distinct position/normal/uv corner), triangles after "
      "triangulation (a convex polygon fanned, a concave one cut into ears). Files a model names "
      "are looked up as the loader does (MTL libraries "
      "beside the OBJ, maps beside their MTL) and marked found or MISSING. A material whose "
      "maps have -s, -o or -clamp options says where its maps are placed.\n\n"
      "Examples:\n"
      "  softrast info model.obj\n"
      "  softrast info assets/*.obj --json | jq .triangles");
}

int info_command(const InfoArgs& args) {
  bool all_loaded = true;
  for (const std::string& path : args.models) {
    ojson info = describe(path);
    if (info.contains("error")) {
      print_error(info["error"].get<std::string>());
      all_loaded = false;
    }
    if (info.contains("warnings")) {
      for (const ojson& w : info["warnings"]) {
        std::fprintf(stderr, "softrast: warning: %s\n", w.get<std::string>().c_str());
      }
    }
    if (args.json) {
      if (!print_line(info.dump(-1, ' ', false, ojson::error_handler_t::replace))) {
        print_error("cannot write the results to the standard output");
        return kExitRuntime;
      }
    } else {
      print_text(info);
    }
  }
  std::fflush(stdout);
  return all_loaded ? 0 : kExitRuntime;
}

}  // namespace softrast::cli
