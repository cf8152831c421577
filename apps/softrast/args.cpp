// apps/softrast/args.cpp: the render command's flags and their help texts. Values are checked
// later (setup.cpp), so every malformed value gets the same style of message.

#include "args.hpp"

#include "debug_flag.hpp"

namespace softrast::cli {
namespace {

void define_output_flags(CLI::App& app, RawArgs& a) {
  app.add_option("MODEL", a.models,
                 "Model files (Wavefront OBJ with the MTL files it names, glTF 2.0 as .gltf or "
                 ".glb, PLY or STL, told by their contents) or folders of them; several are drawn "
                 "together as one scene, each with its own materials. Without MODEL, the built-in "
                 "demo scene")
      ->type_name("MODEL...");
  app.add_option("-o,--out", a.output,
                 "Output image, .png, .jpg or .tga, or - for PNG on the standard output (default "
                 "softrast.png; with --frames, only if given)")
      ->type_name("PATH");
  app.add_option("--size", a.size, "Image size (default 800x600)")->type_name("WxH");
  app.add_option("--frames", a.frames,
                 "Benchmark: time N frames after 2 warm-up frames, print one JSON line")
      ->type_name("N");
  app.add_flag("-q,--quiet", a.quiet, "No progress messages or warnings on stderr");
}

void define_camera_flags(CLI::App& app, RawArgs& a) {
  app.add_option("--eye", a.eye,
                 "Camera position (default: placed by --view, --azimuth, --elevation and --zoom)")
      ->type_name("X,Y,Z");
  app.add_option("--target", a.target, "Point looked at (default: the model's centre)")
      ->type_name("X,Y,Z");
  app.add_option("--up", a.up,
                 "Camera up direction (default: the model's up axis, or its front where --eye is "
                 "straight above or below --target, as in the top and bottom views)")
      ->type_name("X,Y,Z");
  app.add_option("--up-axis", a.up_axis,
                 "The model's up direction: +x, -x, +y, -y, +z or -z (default +y; +z for models "
                 "made Z-up)")
      ->type_name("AXIS");
  app.add_option("--view", a.view,
                 "Side the model is seen from: front, back, left, right, top, bottom or iso "
                 "(default front; from 45 degrees above a model flat along its up axis, and "
                 "right for one flat across the view, which the front would see edge-on)")
      ->type_name("NAME");
  app.add_option("--azimuth", a.azimuth,
                 "Camera angle around the up axis, from the front towards the right (default: "
                 "from --view)")
      ->type_name("DEG");
  app.add_option("--elevation", a.elevation,
                 "Camera angle above the horizon, -90 to 90 (default: from --view)")
      ->type_name("DEG");
  app.add_option("--zoom", a.zoom,
                 "Size of the framed model: 1 fills 90% of the image's width or height, "
                 "whichever limits it, 2 twice that (default 1)")
      ->type_name("F");
  app.add_option("--fov", a.fov, "Vertical field of view in degrees, gluPerspective (default 45)")
      ->type_name("DEG");
  app.add_option("--ortho", a.ortho, "Orthographic box (glOrtho) instead of a perspective")
      ->type_name("L,R,B,T");
  app.add_option("--near", a.near_plane, "Near plane distance (default: fit the model)")
      ->type_name("Z");
  app.add_option("--far", a.far_plane, "Far plane distance (default: fit the model)")
      ->type_name("Z");
}

void define_shading_flags(CLI::App& app, RawArgs& a) {
  app.add_option("--shader", a.shader,
                 "flat, gouraud, texture, phong, normals, depth, wireframe or pbr (default phong; "
                 "pbr for glTF models: metallic-roughness materials under a sky and a key light); "
                 "depth is the depth view (grey by distance), not the depth test (--depth)")
      ->type_name("NAME");
  app.add_flag("--wireframe", a.wireframe, "Draw the visible triangle edges over any shader");
  app.add_option("--edge-color", a.edge_color,
                 "Colour of the --wireframe edges (default 0.05,0.05,0.05)")
      ->type_name("R,G,B");
  app.add_option("--texture", a.texture,
                 "PNG/TGA/JPG texture for texture and phong; overrides the maps (map_Kd) of the "
                 "model's MTL materials")
      ->type_name("PATH");
  app.add_option("--color", a.color,
                 "Albedo for flat, gouraud and phong where the model has no material "
                 "(default 0.9,0.6,0.3)")
      ->type_name("R,G,B");
  app.add_option("--light", a.light,
                 "Direction towards the light, fixed in world space (default: a headlight, "
                 "0.3,0.5,0.8 in the camera's frame, so any view is lit from its upper right)")
      ->type_name("X,Y,Z");
  app.add_option("--light-pos", a.light_pos,
                 "A point light at this position in world space instead of a direction (lights "
                 "every point from where it is, with no fall-off; not with --light)")
      ->type_name("X,Y,Z");
  app.add_option("--maps", a.maps,
                 "Which of the model's maps phong uses: all (diffuse, specular, normal, alpha), "
                 "diffuse (only the colour maps, the plain textured look), none (default all)")
      ->type_name("WHICH");
  app.add_flag("--srgb", a.srgb,
               "Linear workflow: colour textures decoded from sRGB (mipmaps built in linear "
               "space), light computed in linear space, the image encoded to sRGB (default off: "
               "colours read and written as stored)");
  app.add_option("--ambient", a.ambient,
                 "Ambient light of gouraud and phong, 0 to 1 (default 0.15)")
      ->type_name("A");
  app.add_option("--light-intensity", a.light_intensity,
                 "Strength of the diffuse and specular light, 0 to 100 (default 1)")
      ->type_name("I");
  app.add_option("--exposure", a.exposure,
                 "Exposure of the pbr shader in stops, -20 to 20: each +1 doubles the light "
                 "before tone mapping (default 0)")
      ->type_name("EV");
  app.add_option("--alpha", a.alpha,
                 "The model's opacity, 0 to 1, written to the image's alpha channel; with --blend "
                 "alpha what is behind shows through (default 1). See --background for the "
                 "background's")
      ->type_name("A");
  app.add_option("--background", a.background,
                 "Background colour, alpha 0 for a transparent PNG (default 0.1,0.1,0.1,1)")
      ->type_name("R,G,B[,A]");
  app.add_option(
         "--filter", a.filter,
         "Texture filter: nearest, bilinear or trilinear (mipmapped: bilinear in the two mip "
         "levels nearest the level of detail, blended; no shimmer where the texture is "
         "minified) (default bilinear, as SCENES.md's pipeline has it; trilinear for the "
         "demo scene, whose floor reaches the horizon)")
      ->type_name("MODE");
  app.add_flag("--shadows", a.shadows,
               "Shadows of the directional light for phong: a depth map from the light over the "
               "model's bounds, 3x3 percentage-closer filtering, slope-scaled bias");
  app.add_option("--wrap", a.wrap, "Texture wrap: repeat, clamp or mirror (default repeat)")
      ->type_name("MODE");
  app.add_option("--debug", a.debug, kDebugViewHelp)->type_name("VIEW");
}

void define_state_flags(CLI::App& app, RawArgs& a) {
  app.add_option("--cull", a.cull,
                 "Face culling: none, back or front (default none: both faces drawn, a back face "
                 "lit as its front; back skips back faces, as the benchmark scenes do)")
      ->type_name("MODE");
  app.add_option("--front-face", a.front_face, "Front-facing winding: ccw or cw (default ccw)")
      ->type_name("MODE");
  app.add_option("--depth", a.depth,
                 "Depth test, which surface hides which: less, lequal, equal, greater, gequal, "
                 "notequal, always, never or off (default less); not the depth view (--shader "
                 "depth)")
      ->type_name("FUNC");
  app.add_option("--blend", a.blend, "Blending: opaque, alpha or add (default opaque)")
      ->type_name("MODE");
  app.add_option("--raster", a.raster, "Rasterizer: edge (tiles) or scanline (default edge)")
      ->type_name("ALGO");
  app.add_option("--msaa", a.msaa,
                 "Multisample anti-aliasing: 1, 2, 4 or 8 samples per pixel at the standard "
                 "D3D/Vulkan positions, shaded once per pixel and triangle (default 1)")
      ->type_name("N");
  app.add_option("--threads", a.threads,
                 "Threads to render with: 0 for every core (default 0; the image is the same)")
      ->type_name("N");
  app.add_flag("--reference-path", a.reference_path,
               "Render with the slow single-threaded immediate path that the tests use as the "
               "oracle (same image)");
}

}  // namespace

void define_render_flags(CLI::App& app, RawArgs& args) {
  define_output_flags(app, args);
  define_camera_flags(app, args);
  define_shading_flags(app, args);
  define_state_flags(app, args);
  // Image output (io): JPEG quality.
  app.add_option("--quality", args.quality, "JPEG quality for .jpg output, 1..100 (default 90)")
      ->type_name("Q");
}

}  // namespace softrast::cli
