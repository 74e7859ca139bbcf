// read_mesh: dispatch on the file extension, then the docs/SCENE.md "Meshes" validation.
#include "soft_tissue_cutting/io/mesh_reader.hpp"

#include "format_readers.hpp"
#include "text_cursor.hpp"

#include <new>

namespace stc {
namespace {

std::string extension_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return io::lower(std::string_view(path).substr(dot));
}

io::RawMesh read_raw(const std::string& path, const MeshReadOptions& options) {
  const std::string ext = extension_of(path);
  if (ext == ".msh") return io::read_gmsh(path, io::read_file(path));
  if (ext == ".node") return io::read_tetgen(path);
  if (ext == ".vtk") return io::read_vtk_legacy(path, io::read_file(path));
  if (ext == ".vtu") return io::read_vtu(path, io::read_file(path));
  if (ext == ".obj")
    return io::tetrahedralize_surface(path, io::read_obj(path, io::read_file(path)),
                                      options.tetgen_switches);
  if (ext == ".stl")
    return io::tetrahedralize_surface(path, io::read_stl(path, io::read_file(path)),
                                      options.tetgen_switches);
  if (ext == ".off")
    return io::tetrahedralize_surface(path, io::read_off(path, io::read_file(path)),
                                      options.tetgen_switches);
  if (ext == ".ele")
    io::fail(path, 0, "name a TetGen mesh by its .node file (the .ele beside it is read too)");
  io::fail(path, 0,
           "unknown mesh format '" + ext +
               "' (supported: .msh .node .vtk .vtu, closed surfaces .obj .stl .off)");
}

}  // namespace

TetMesh read_mesh(const std::string& path, const MeshReadOptions& options,
                  std::vector<std::string>* warnings) {
  try {
    io::RawMesh raw = read_raw(path, options);
    validate_tet_mesh(raw.mesh, path, warnings, &raw.lines);
    return std::move(raw.mesh);
  } catch (const std::bad_alloc&) {
    io::fail(path, 0, "out of memory while reading (corrupt counts or a mesh too large)");
  } catch (const std::length_error&) {
    io::fail(path, 0, "out of memory while reading (corrupt counts or a mesh too large)");
  }
}

}  // namespace stc
