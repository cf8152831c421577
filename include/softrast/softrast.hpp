// softrast/softrast.hpp: the whole public API in one include (custom shaders: shader.hpp).
#pragma once

#include "softrast/camera.hpp"        // gluLookAt / gluPerspective / glOrtho camera
#include "softrast/debug_view.hpp"    // tile grid, overdraw, per-tile cost, triangle colours
#include "softrast/framebuffer.hpp"   // RGBA8 colour + float depth render target
#include "softrast/image.hpp"         // images and their files
#include "softrast/mesh.hpp"          // indexed meshes and the OBJ/MTL loader
#include "softrast/render_state.hpp"  // culling, depth, blending, rasterizer choice
#include "softrast/renderer.hpp"      // render_mesh with the built-in shaders, the demo scene
#include "softrast/status.hpp"        // Status and Result<T>
#include "softrast/texture.hpp"       // textures and samplers
