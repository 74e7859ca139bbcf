// Helpers shared by the mesh I/O tests: a temp dir, file writers for every input format
// (generated from a TetMesh so each format is tested on the same known mesh), and error checks.
#pragma once

#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/io/vtk_writer.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace stc::test {

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/stc_io_XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

inline std::string write_file(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary);
  out << content;
  return path;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// A 2 x 1 x 1 box of 12 tets: small enough to read in a failure message.
inline TetMesh small_box() {
  GeneratorParams g;
  g.type = "box";
  g.size = Vec3(2.0, 1.0, 1.0);
  g.cells = {2, 1, 1};
  return make_box_mesh(g);
}

// Raw binary value in the given byte order.
template <typename T>
std::string bin(T v, bool big_endian = false) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));  // tests run on little-endian hosts
  return std::string(b, sizeof(T));
}

// ---- writers for the formats read_mesh supports (node tags offset to test mapping)
inline std::string gmsh_v1(const TetMesh& m, int tag0 = 1) {
  std::string s = "$NOD\n" + std::to_string(m.num_nodes()) + "\n";
  for (int i = 0; i < m.num_nodes(); ++i)
    s += std::to_string(tag0 + i) + " " + fmt(m.nodes[i].x()) + " " + fmt(m.nodes[i].y()) + " " +
         fmt(m.nodes[i].z()) + "\n";
  s += "$ENDNOD\n$ELM\n" + std::to_string(m.num_tets()) + "\n";
  for (int t = 0; t < m.num_tets(); ++t) {
    s += std::to_string(t + 1) + " 4 1 1 4";
    for (int v : m.tets[t]) s += " " + std::to_string(tag0 + v);
    s += "\n";
  }
  return s + "$ENDELM\n";
}

inline std::string gmsh_v22(const TetMesh& m, int tag0 = 1) {
  std::string s =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 "
      "\"tissue\"\n$EndPhysicalNames\n";
  s += "$Nodes\n" + std::to_string(m.num_nodes()) + "\n";
  for (int i = 0; i < m.num_nodes(); ++i)
    s += std::to_string(tag0 + 10 * i) + " " + fmt(m.nodes[i].x()) + " " + fmt(m.nodes[i].y()) +
         " " + fmt(m.nodes[i].z()) + "\n";
  s += "$EndNodes\n$Elements\n" + std::to_string(m.num_tets() + 2) + "\n";
  s += "1 15 2 0 1 " + std::to_string(tag0) + "\n";  // a point element: ignored
  s += "2 2 2 0 1 " + std::to_string(tag0) + " " + std::to_string(tag0 + 10) + " " +
       std::to_string(tag0 + 20) + "\n";  // a triangle: ignored
  for (int t = 0; t < m.num_tets(); ++t) {
    s += std::to_string(t + 3) + " 4 2 0 1";
    for (int v : m.tets[t]) s += " " + std::to_string(tag0 + 10 * v);
    s += "\n";
  }
  return s + "$EndElements\n";
}

inline std::string gmsh_v41(const TetMesh& m) {
  // Two node blocks (the first parametric on a curve), tags descending to test the mapping.
  const int n = m.num_nodes();
  const int half = n / 2;
  auto tag = [&](int i) { return 1000 - i; };
  std::string s =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n";
  s += "$Nodes\n2 " + std::to_string(n) + " " + std::to_string(tag(n - 1)) + " 1000\n";
  s += "1 1 1 " + std::to_string(half) + "\n";
  for (int i = 0; i < half; ++i) s += std::to_string(tag(i)) + "\n";
  for (int i = 0; i < half; ++i)
    s += fmt(m.nodes[i].x()) + " " + fmt(m.nodes[i].y()) + " " + fmt(m.nodes[i].z()) + " 0.5\n";
  s += "3 1 0 " + std::to_string(n - half) + "\n";
  for (int i = half; i < n; ++i) s += std::to_string(tag(i)) + "\n";
  for (int i = half; i < n; ++i)
    s += fmt(m.nodes[i].x()) + " " + fmt(m.nodes[i].y()) + " " + fmt(m.nodes[i].z()) + "\n";
  s += "$EndNodes\n$Elements\n2 " + std::to_string(m.num_tets() + 1) + " 1 " +
       std::to_string(m.num_tets() + 1) + "\n";
  s += "1 1 1 1\n1 " + std::to_string(tag(0)) + " " + std::to_string(tag(1)) + "\n";  // a line
  s += "3 1 4 " + std::to_string(m.num_tets()) + "\n";
  for (int t = 0; t < m.num_tets(); ++t) {
    s += std::to_string(t + 2);
    for (int v : m.tets[t]) s += " " + std::to_string(tag(v));
    s += "\n";
  }
  return s + "$EndElements\n";
}

inline std::string gmsh_v22_binary(const TetMesh& m) {
  std::string s = "$MeshFormat\n2.2 1 8\n" + bin<int>(1) + "\n$EndMeshFormat\n";
  s += "$Nodes\n" + std::to_string(m.num_nodes()) + "\n";
  for (int i = 0; i < m.num_nodes(); ++i)
    s += bin<int>(i + 1) + bin(m.nodes[i].x()) + bin(m.nodes[i].y()) + bin(m.nodes[i].z());
  s += "\n$EndNodes\n$Elements\n" + std::to_string(m.num_tets() + 1) + "\n";
  s += bin<int>(15) + bin<int>(1) + bin<int>(2) + bin<int>(1) + bin<int>(0) + bin<int>(0) +
       bin<int>(1);
  s += bin<int>(4) + bin<int>(m.num_tets()) + bin<int>(2);
  for (int t = 0; t < m.num_tets(); ++t) {
    s += bin<int>(t + 2) + bin<int>(0) + bin<int>(0);
    for (int v : m.tets[t]) s += bin<int>(v + 1);
  }
  return s + "\n$EndElements\n";
}

inline std::string gmsh_v41_binary(const TetMesh& m) {
  using u64 = std::uint64_t;
  const u64 n = static_cast<u64>(m.num_nodes()), nt = static_cast<u64>(m.num_tets());
  std::string s = "$MeshFormat\n4.1 1 8\n" + bin<int>(1) + "\n$EndMeshFormat\n";
  s += "$Nodes\n" + bin<u64>(1) + bin<u64>(n) + bin<u64>(1) + bin<u64>(n);
  s += bin<int>(3) + bin<int>(1) + bin<int>(0) + bin<u64>(n);
  for (u64 i = 0; i < n; ++i) s += bin<u64>(i + 1);
  for (const Vec3& x : m.nodes) s += bin(x.x()) + bin(x.y()) + bin(x.z());
  s += "\n$EndNodes\n$Elements\n" + bin<u64>(1) + bin<u64>(nt) + bin<u64>(1) + bin<u64>(nt);
  s += bin<int>(3) + bin<int>(1) + bin<int>(4) + bin<u64>(nt);
  for (u64 t = 0; t < nt; ++t) {
    s += bin<u64>(t + 1);
    for (int v : m.tets[t]) s += bin<u64>(static_cast<u64>(v) + 1);
  }
  return s + "\n$EndElements\n";
}

// TetGen .node/.ele with `base` 0 or 1, attributes and markers.
inline std::pair<std::string, std::string> tetgen_files(const TetMesh& m, int base) {
  std::string node = "# generated\n" + std::to_string(m.num_nodes()) + " 3 1 1\n";
  for (int i = 0; i < m.num_nodes(); ++i)
    node += std::to_string(base + i) + " " + fmt(m.nodes[i].x()) + " " + fmt(m.nodes[i].y()) + " " +
            fmt(m.nodes[i].z()) + " 0.0 1  # node\n";
  std::string ele = std::to_string(m.num_tets()) + " 4 1\n";
  for (int t = 0; t < m.num_tets(); ++t) {
    ele += std::to_string(base + t);
    for (int v : m.tets[t]) ele += " " + std::to_string(base + v);
    ele += " 7\n";
  }
  return {node, ele};
}

inline std::string vtk_ascii(const TetMesh& m, bool v51 = false) {
  std::string s = std::string("# vtk DataFile Version ") + (v51 ? "5.1" : "3.0") +
                  "\ntest\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS " +
                  std::to_string(m.num_nodes()) + " double\n";
  for (const Vec3& x : m.nodes) s += fmt(x.x()) + " " + fmt(x.y()) + " " + fmt(x.z()) + "\n";
  const int nt = m.num_tets();
  if (v51) {
    // one extra vertex cell (type 1) to be ignored
    s += "CELLS " + std::to_string(nt + 2) + " " + std::to_string(4 * nt + 1) +
         "\nOFFSETS vtktypeint64\n";
    for (int t = 0; t <= nt; ++t) s += std::to_string(4 * t) + " ";
    s += std::to_string(4 * nt + 1) + "\nCONNECTIVITY vtktypeint64\n";
    for (const Tet& t : m.tets)
      s += std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + " " +
           std::to_string(t[3]) + "\n";
    s += "0\nCELL_TYPES " + std::to_string(nt + 1) + "\n";
    for (int t = 0; t < nt; ++t) s += "10\n";
    s += "1\n";
  } else {
    s += "CELLS " + std::to_string(nt + 1) + " " + std::to_string(5 * nt + 2) + "\n";
    for (const Tet& t : m.tets)
      s += "4 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) +
           " " + std::to_string(t[3]) + "\n";
    s += "1 0\nCELL_TYPES " + std::to_string(nt + 1) + "\n";
    for (int t = 0; t < nt; ++t) s += "10\n";
    s += "1\n";
  }
  return s + "POINT_DATA " + std::to_string(m.num_nodes()) + "\n";
}

inline std::string vtk_binary(const TetMesh& m, bool use_float) {
  std::string s = "# vtk DataFile Version 3.0\ntest\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS " +
                  std::to_string(m.num_nodes()) + (use_float ? " float\n" : " double\n");
  for (const Vec3& x : m.nodes)
    for (int d = 0; d < 3; ++d)
      s += use_float ? bin(static_cast<float>(x[d]), true) : bin(x[d], true);
  const int nt = m.num_tets();
  s += "\nCELLS " + std::to_string(nt) + " " + std::to_string(5 * nt) + "\n";
  for (const Tet& t : m.tets) {
    s += bin<std::int32_t>(4, true);
    for (int v : t) s += bin<std::int32_t>(v, true);
  }
  s += "\nCELL_TYPES " + std::to_string(nt) + "\n";
  for (int t = 0; t < nt; ++t) s += bin<std::int32_t>(10, true);
  return s + "\n";
}

inline std::string vtu_ascii(const TetMesh& m) {
  const int nt = m.num_tets();
  std::string s =
      "<?xml version=\"1.0\"?>\n<!-- test file -->\n<VTKFile type=\"UnstructuredGrid\" "
      "version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n";
  s += "<Piece NumberOfPoints=\"" + std::to_string(m.num_nodes()) + "\" NumberOfCells='" +
       std::to_string(nt + 1) + "'>\n";
  s += "<PointData Scalars=\"s\"><DataArray type=\"Float64\" Name=\"s\" format=\"ascii\">";
  for (int i = 0; i < m.num_nodes(); ++i) s += "0 ";
  s += "</DataArray></PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" "
       "format=\"ascii\">\n";
  for (const Vec3& x : m.nodes) s += fmt(x.x()) + " " + fmt(x.y()) + " " + fmt(x.z()) + "\n";
  s += "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" "
       "format=\"ascii\">\n";
  for (const Tet& t : m.tets)
    s += std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + " " +
         std::to_string(t[3]) + "\n";
  s += "0 1 2\n</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (int t = 1; t <= nt; ++t) s += std::to_string(4 * t) + "\n";
  s += std::to_string(4 * nt + 3) +
       "\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int t = 0; t < nt; ++t) s += "10\n";
  s += "5\n</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  return s;
}

// The boundary of a mesh as surface files.
inline std::string obj_surface(const TetMesh& m) {
  const BoundarySurface b = extract_boundary_surface(m);
  std::string s = "# box\no box\n";
  for (const Vec3& x : m.nodes) s += "v " + fmt(x.x()) + " " + fmt(x.y()) + " " + fmt(x.z()) + "\n";
  for (const auto& t : b.triangles)
    s += "f " + std::to_string(t.nodes[0] + 1) + "//1 " + std::to_string(t.nodes[1] + 1) + "//1 " +
         std::to_string(t.nodes[2] + 1) + "//1\n";
  return s;
}

inline std::string off_surface(const TetMesh& m) {
  const BoundarySurface b = extract_boundary_surface(m);
  std::string s =
      "OFF\n" + std::to_string(m.num_nodes()) + " " + std::to_string(b.triangles.size()) + " 0\n";
  for (const Vec3& x : m.nodes) s += fmt(x.x()) + " " + fmt(x.y()) + " " + fmt(x.z()) + "\n";
  for (const auto& t : b.triangles)
    s += "3 " + std::to_string(t.nodes[0]) + " " + std::to_string(t.nodes[1]) + " " +
         std::to_string(t.nodes[2]) + "\n";
  return s;
}

inline std::string stl_ascii(const TetMesh& m) {
  const BoundarySurface b = extract_boundary_surface(m);
  std::string s = "solid box\n";
  for (const auto& t : b.triangles) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (int v : t.nodes)
      s += "   vertex " + fmt(m.nodes[v].x()) + " " + fmt(m.nodes[v].y()) + " " +
           fmt(m.nodes[v].z()) + "\n";
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid box\n";
}

inline std::string stl_binary(const TetMesh& m) {
  const BoundarySurface b = extract_boundary_surface(m);
  std::string s = "solid but actually binary";
  s.resize(80, ' ');
  s += bin<std::uint32_t>(static_cast<std::uint32_t>(b.triangles.size()));
  for (const auto& t : b.triangles) {
    for (int k = 0; k < 3; ++k) s += bin(0.0f);
    for (int v : t.nodes)
      for (int d = 0; d < 3; ++d) s += bin(static_cast<float>(m.nodes[v][d]));
    s += bin<std::uint16_t>(0);
  }
  return s;
}

// The MeshError message of reading `path`, or "" when it loaded.
inline std::string mesh_error(const std::string& path, const MeshReadOptions& options = {}) {
  try {
    read_mesh(path, options);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

}  // namespace stc::test
