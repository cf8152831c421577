// io/obj_loader.hpp: the OBJ loader with its byte limits as parameters, so that tests can check
// the limits with small files. load_obj (softrast/mesh.hpp) is this with the documented limits.
#pragma once

#include <cstdint>
#include <string>

#include "softrast/mesh.hpp"

namespace softrast::detail {

Result<Mesh> load_obj(const std::string& path, int64_t max_obj_bytes, int64_t max_mtl_bytes);

}  // namespace softrast::detail
