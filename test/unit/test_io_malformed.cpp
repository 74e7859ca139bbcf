// Malformed input for every reader (docs/SCENE.md "Meshes"): each case must throw MeshError with
// one line that starts with the file's path and, where a line applies, names it. Plus a fuzz loop:
// random byte mutations of valid files load or throw MeshError, never anything else.
#include "test_io_util.hpp"

#include <random>

namespace stc {
namespace {

using test::TempDir;
using test::write_file;

struct File {
  std::string name;
  std::string content;
};

struct BadCase {
  const char* name;
  std::vector<File> files;  // files[0] is read; its path (or error_file's) starts the message
  int line;                 // 0: no line expected
  const char* fragment;
  const char* error_name = nullptr;  // the file the message names, when not files[0]
  std::string switches = "pq1.4Q";
};

// A single positive tet in Gmsh format 1, lines 1-11; `nodes` / `elements` replace lines 3-6 / 10.
std::string v1(const std::string& nodes = "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n",
               const std::string& elements = "1 4 1 1 4 1 2 3 4\n", int n = 4, int m = 1) {
  return "$NOD\n" + std::to_string(n) + "\n" + nodes + "$ENDNOD\n$ELM\n" + std::to_string(m) +
         "\n" + elements + "$ENDELM\n";
}
// Nodes for face checks: 1-3 a triangle at z = 0, 4 and 5 above it, 6 below.
const std::string kSixNodes = "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0.2 0.2 0.5\n6 0 0 -1\n";

std::string v22(const std::string& body) { return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n" + body; }
const std::string kV22Nodes =
    "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";  // lines 4-10

std::string tetgen_node(const std::string& points = "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n",
                        const std::string& head = "4 3 0 0\n") {
  return head + points;
}
const std::string kEle = "1 4 0\n1 1 2 3 4\n";

std::string vtk(
    const std::string& points = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n",
    const std::string& cells = "CELLS 1 5\n4 0 1 2 3\n",
    const std::string& types = "CELL_TYPES 1\n10\n",
    const std::string& head = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n") {
  return head + "POINTS 4 double\n" + points + cells + types;  // POINTS on line 5
}

std::string vtu(const std::string& points = "0 0 0 1 0 0 0 1 0 0 0 1",
                const std::string& cells =
                    "<DataArray Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray>\n"
                    "<DataArray Name=\"offsets\" format=\"ascii\">4</DataArray>\n"
                    "<DataArray Name=\"types\" format=\"ascii\">10</DataArray>\n",
                const std::string& root = "<VTKFile type=\"UnstructuredGrid\">\n") {
  return root + "<UnstructuredGrid><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\">\n" +
         "<Points><DataArray NumberOfComponents=\"3\" format=\"ascii\">\n" + points +
         "\n</DataArray></Points>\n<Cells>\n" + cells +
         "</Cells>\n</Piece></UnstructuredGrid>\n</VTKFile>\n";
}

std::string cut(const std::string& s, double fraction) {
  return s.substr(0, static_cast<std::size_t>(s.size() * fraction));
}

std::vector<BadCase> cases() {
  const TetMesh box = test::small_box();
  std::vector<BadCase> c;
  // ---- Gmsh format 1
  c.push_back({"v1_truncated",
               {{"a.msh", v1().substr(0, v1().find("$ENDELM"))}},
               11,
               "unexpected end of file, expected $ENDELM"});
  c.push_back({"v1_truncated_nodes",
               {{"a.msh", cut(v1(), 0.3)}},
               2,
               "exceeds what the file holds (truncated?)"});
  c.push_back({"v1_nan",
               {{"a.msh", v1("1 0 0 0\n2 nan 0 0\n3 0 1 0\n4 0 0 1\n")}},
               4,
               "non-finite x coordinate"});
  c.push_back({"v1_inf",
               {{"a.msh", v1("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 -inf\n")}},
               6,
               "non-finite z coordinate"});
  c.push_back({"v1_huge_number",
               {{"a.msh", v1("1 0 0 0\n2 1e999 0 0\n3 0 1 0\n4 0 0 1\n")}},
               4,
               "expected x coordinate"});
  c.push_back({"v1_text_coordinate",
               {{"a.msh", v1("1 0 0 0\n2 1 zero 0\n3 0 1 0\n4 0 0 1\n")}},
               4,
               "expected y coordinate"});
  c.push_back({"v1_short_node_line",
               {{"a.msh", v1("1 0 0 0\n2 1 0\n3 0 1 0\n4 0 0 1\n")}},
               4,
               "fewer than 4 fields"});
  c.push_back(
      {"v1_undefined_tag",
       {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"), "1 4 1 1 4 1 2 3 9\n")}},
       10,
       "undefined node tag 9"});
  c.push_back(
      {"v1_repeated_node",
       {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"), "1 4 1 1 4 1 2 3 3\n")}},
       10,
       "twice"});
  c.push_back({"v1_zero_volume",
               {{"a.msh", v1("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n")}},
               10,
               "zero volume"});
  c.push_back({"v1_duplicate_tag",
               {{"a.msh", v1("1 0 0 0\n1 1 0 0\n3 0 1 0\n4 0 0 1\n")}},
               4,
               "duplicate node tag 1"});
  c.push_back({"v1_node_count_too_big",
               {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"),
                             "1 4 1 1 4 1 2 3 4\n", 5)}},
               7,
               "after 4 of 5 nodes"});
  c.push_back({"v1_node_count_too_small",
               {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"),
                             "1 4 1 1 4 1 2 3 4\n", 3)}},
               6,
               "expected $ENDNOD"});
  c.push_back({"v1_absurd_count",
               {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"),
                             "1 4 1 1 4 1 2 3 4\n", 2000000000)}},
               2,
               "exceeds what the file holds"});
  c.push_back({"v1_negative_count",
               {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"),
                             "1 4 1 1 4 1 2 3 4\n", 4, -1)}},
               9,
               "negative element count"});
  c.push_back(
      {"v1_declared_nodes_mismatch",
       {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"), "1 4 1 1 4 1 2 3\n")}},
       10,
       "declares 4 nodes but lists 3"});
  c.push_back({"v1_tet_with_5_nodes",
               {{"a.msh",
                 v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"), "1 4 1 1 5 1 2 3 4 4\n")}},
               10,
               "tetrahedron with 5 nodes"});
  c.push_back(
      {"v1_no_tets",
       {{"a.msh", v1(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"), "1 2 1 1 3 1 2 3\n")}},
       0,
       "no tetrahedra"});
  c.push_back({"v1_garbage_bytes",
               {{"a.msh", std::string("\x01\x02\xff garbage\n", 12) + v1()}},
               1,
               "expected a section header"});
  c.push_back({"v1_tangled",
               {{"a.msh", v1(kSixNodes, "1 4 1 1 4 1 2 3 4\n2 4 1 1 4 1 2 3 5\n", 6, 2)}},
               0,
               "same side"});
  c.push_back({"v1_face_in_three_tets",
               {{"a.msh",
                 v1(kSixNodes, "1 4 1 1 4 1 2 3 4\n2 4 1 1 4 1 3 2 6\n3 4 1 1 4 1 2 3 5\n", 6, 3)}},
               0,
               "more than two"});
  c.push_back({"v1_duplicated_tet",
               {{"a.msh", v1(kSixNodes, "1 4 1 1 4 1 2 3 4\n2 4 1 1 4 2 1 4 3\n", 6, 2)}},
               0,
               "face(s) shared"});
  c.push_back({"v1_mixed_orientation",
               {{"a.msh", v1(kSixNodes, "1 4 1 1 4 1 2 3 4\n2 4 1 1 4 1 2 3 6\n", 6, 2)}},
               13,
               "mixed tetrahedron orientation"});
  c.push_back({"empty_msh", {{"a.msh", ""}}, 0, "not a Gmsh mesh"});
  // ---- Gmsh 2.2 / 4.1
  c.push_back({"v22_version",
               {{"a.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n"}},
               2,
               "unsupported Gmsh format version"});
  c.push_back({"v22_no_format", {{"a.msh", kV22Nodes}}, 1, "without a preceding $MeshFormat"});
  c.push_back({"v22_bad_end_format",
               {{"a.msh", "$MeshFormat\n2.2 0 8\n$EndFormat\n"}},
               3,
               "expected $EndMeshFormat"});
  c.push_back({"v22_unterminated_section",
               {{"a.msh", v22("$Comments\nhello\n" + kV22Nodes)}},
               4,
               "has no $EndComments"});
  c.push_back({"v22_bad_tag_count",
               {{"a.msh", v22(kV22Nodes + "$Elements\n1\n1 4 9 1 2 3 4\n$EndElements\n")}},
               13,
               "bad number of tags"});
  c.push_back({"v22_elements_before_nodes",
               {{"a.msh", v22("$Elements\n0\n$EndElements\n" + kV22Nodes)}},
               4,
               "$Elements before $Nodes"});
  c.push_back({"v22_missing_end_elements",
               {{"a.msh", v22(kV22Nodes + "$Elements\n1\n1 4 2 0 1 1 2 3 4\n")}},
               14,
               "expected $EndElements"});
  c.push_back(
      {"v22_binary_truncated", {{"a.msh", cut(test::gmsh_v22_binary(box), 0.3)}}, 0, "truncated"});
  {
    std::string s = test::gmsh_v22_binary(box);
    s.replace(s.find("\n2.2 1 8\n") + 9, 4, std::string("\x02\0\0\0", 4));
    c.push_back({"v22_binary_endianness", {{"a.msh", s}}, 3, "endianness marker"});
  }
  c.push_back({"v41_block_count",
               {{"a.msh",
                 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 5 1 5\n3 1 0 4\n1\n2\n3\n4\n0 0 "
                 "0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"}},
               0,
               "header says 5"});
  c.push_back(
      {"v41_short_tet_line",
       {{"a.msh",
         "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 "
         "0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3\n$EndElements\n"}},
       19,
       "needs a tag and 4 node tags"});
  c.push_back(
      {"v41_binary_truncated", {{"a.msh", cut(test::gmsh_v41_binary(box), 0.7)}}, 0, "truncated"});
  c.push_back({"v40_refused",
               {{"a.msh", "$MeshFormat\n4 0 8\n$EndMeshFormat\n"}},
               2,
               "unsupported Gmsh format version"});
  // ---- TetGen
  c.push_back({"tetgen_first_index",
               {{"a.node", tetgen_node("2 0 0 0\n3 1 0 0\n4 0 1 0\n5 0 0 1\n")}, {"a.ele", kEle}},
               2,
               "first point index must be 0 or 1"});
  c.push_back({"tetgen_not_consecutive",
               {{"a.node", tetgen_node("1 0 0 0\n2 1 0 0\n4 0 1 0\n5 0 0 1\n")}, {"a.ele", kEle}},
               4,
               "consecutively"});
  c.push_back({"tetgen_missing_ele", {{"a.node", tetgen_node()}}, 0, "cannot open file", "a.ele"});
  c.push_back({"tetgen_index_out_of_range",
               {{"a.node", tetgen_node()}, {"a.ele", "# tets\n1 4 0\n1 1 2 3 5\n"}},
               3,
               "node index 5 out of range [1, 4]",
               "a.ele"});
  c.push_back({"tetgen_field_count",
               {{"a.node", tetgen_node("1 0 0 0\n2 1 0 0 7\n3 0 1 0\n4 0 0 1\n")}, {"a.ele", kEle}},
               3,
               "has 5 fields, expected 4"});
  c.push_back(
      {"tetgen_dimension",
       {{"a.node", tetgen_node(std::string("1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"), "4 2 0 0\n")},
        {"a.ele", kEle}},
       1,
       "dimension 2 out of range"});
  c.push_back({"tetgen_triangles",
               {{"a.node", tetgen_node()}, {"a.ele", "1 3 0\n1 1 2 3\n"}},
               1,
               "nodes per tetrahedron 3",
               "a.ele"});
  c.push_back({"tetgen_nan",
               {{"a.node", tetgen_node("1 0 0 0\n2 1 0 0\n3 0 NaN 0\n4 0 0 1\n")}, {"a.ele", kEle}},
               4,
               "non-finite y coordinate"});
  c.push_back({"tetgen_extra_data",
               {{"a.node", tetgen_node()}, {"a.ele", kEle + "2 1 2 3 4\n"}},
               3,
               "unexpected data after",
               "a.ele"});
  // ---- VTK legacy
  c.push_back(
      {"vtk_header",
       {{"a.vtk", vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 5\n4 0 1 2 3\n",
                      "CELL_TYPES 1\n10\n", "# vtk file\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n")}},
       1,
       "not a VTK legacy file"});
  c.push_back({"vtk_polydata",
               {{"a.vtk",
                 vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n",
                     "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n")}},
               4,
               "only DATASET UNSTRUCTURED_GRID"});
  c.push_back({"vtk_mode",
               {{"a.vtk",
                 vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n",
                     "# vtk DataFile Version 3.0\nt\nTEXT\nDATASET UNSTRUCTURED_GRID\n")}},
               3,
               "ASCII or BINARY"});
  c.push_back({"vtk_types_count",
               {{"a.vtk", vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 5\n4 0 1 2 3\n",
                              "CELL_TYPES 2\n10\n10\n")}},
               12,
               "CELL_TYPES has 2 cells, CELLS has 1"});
  c.push_back({"vtk_tet_with_3_points",
               {{"a.vtk", vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 4\n3 0 1 2\n")}},
               11,
               "with 3 points"});
  c.push_back({"vtk_point_out_of_range",
               {{"a.vtk", vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 5\n4 0 1 2 4\n")}},
               11,
               "refers to point 4"});
  c.push_back({"vtk_cells_size",
               {{"a.vtk", vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 6\n4 0 1 2 3 3\n")}},
               10,
               "does not match"});
  c.push_back({"vtk_nan",
               {{"a.vtk", vtk("0 0 0\n1 0 0\n0 1 0\n0 0 nan\n")}},
               9,
               "non-finite z coordinate"});
  c.push_back({"vtk_no_cell_types",
               {{"a.vtk", vtk("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "CELLS 1 5\n4 0 1 2 3\n", "")}},
               0,
               "no CELL_TYPES"});
  c.push_back({"vtk_truncated", {{"a.vtk", cut(vtk(), 0.8)}}, 0, "unexpected end of file"});
  c.push_back({"vtk_binary_truncated",
               {{"a.vtk", cut(test::vtk_binary(box, false), 0.5)}},
               5,
               "truncated binary"});
  c.push_back(
      {"vtk_point_type",
       {{"a.vtk",
         "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 int\n"}},
       5,
       "float or double"});
  c.push_back({"vtk51_bad_offsets",
               {{"a.vtk",
                 "# vtk DataFile Version 5.1\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 "
                 "double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 2 4\nOFFSETS vtktypeint64\n1 "
                 "4\nCONNECTIVITY vtktypeint64\n0 1 2 3\nCELL_TYPES 1\n10\n"}},
               7,
               "OFFSETS must start at 0"});
  // ---- VTK XML
  c.push_back({"vtu_not_vtk", {{"a.vtu", "<Other/>\n"}}, 1, "not a VTK XML file"});
  c.push_back({"vtu_polydata",
               {{"a.vtu", vtu("0 0 0 1 0 0 0 1 0 0 0 1", "", "<VTKFile type=\"PolyData\">\n")}},
               1,
               "must be UnstructuredGrid"});
  c.push_back(
      {"vtu_binary",
       {{"a.vtu", vtu("0 0 0 1 0 0 0 1 0 0 0 1",
                      "<DataArray Name=\"connectivity\" format=\"binary\">AAAA</DataArray>\n")}},
       7,
       "only ascii is supported"});
  c.push_back(
      {"vtu_missing_offsets",
       {{"a.vtu",
         vtu("0 0 0 1 0 0 0 1 0 0 0 1",
             "<DataArray Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray>\n<DataArray "
             "Name=\"types\" format=\"ascii\">10</DataArray>\n")}},
       2,
       "needs connectivity, offsets and types"});
  c.push_back(
      {"vtu_nan", {{"a.vtu", vtu("0 0 0 1 0 0\n0 1 0 0 0 nan")}}, 5, "non-finite z coordinate"});
  c.push_back(
      {"vtu_short_points", {{"a.vtu", vtu("0 0 0 1 0 0 0 1 0 0 0")}}, 5, "expected z coordinate"});
  c.push_back({"vtu_truncated", {{"a.vtu", cut(vtu(), 0.5)}}, 0, "unterminated"});
  c.push_back(
      {"vtu_bad_index",
       {{"a.vtu",
         vtu("0 0 0 1 0 0 0 1 0 0 0 1",
             "<DataArray Name=\"connectivity\" format=\"ascii\">0 1 2 7</DataArray>\n<DataArray "
             "Name=\"offsets\" format=\"ascii\">4</DataArray>\n<DataArray Name=\"types\" "
             "format=\"ascii\">10</DataArray>\n")}},
       7,
       "refers to point 7"});
  // ---- surfaces
  {
    std::string open = test::obj_surface(box);
    open.erase(open.rfind("f "));
    c.push_back({"obj_open", {{"s.obj", open}}, 0, "surface is not closed"});
  }
  c.push_back({"obj_index",
               {{"s.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"}},
               4,
               "vertex index 4 out of range"});
  c.push_back({"obj_statement", {{"s.obj", "v 0 0 0\ncurv 1 2\n"}}, 2, "unknown OBJ statement"});
  c.push_back({"obj_nan", {{"s.obj", "v 0 0 0\nv 1 nan 0\n"}}, 2, "non-finite y coordinate"});
  c.push_back({"obj_degenerate",
               {{"s.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\nf 1 2 3\nf 1 3 2\nf 2 3 1\n"}},
               4,
               "degenerate triangle"});
  {
    // Two boxes sharing only an edge: that edge is used by four triangles.
    TetMesh two = box;
    const int n = two.num_nodes();
    for (int i = 0; i < n; ++i) two.nodes.push_back(box.nodes[i] + Vec3(2, 1, 0));
    for (int t = 0; t < box.num_tets(); ++t) {
      Tet tet = box.tets[t];
      for (int& v : tet) v += n;
      two.tets.push_back(tet);
    }
    // Merge the second box's corner edge (x=2,y=1) with the first's (x=2,y=1).
    // STL merges equal coordinates, so the boxes share the vertical edge at x = 2, y = 1.
    c.push_back(
        {"stl_non_manifold", {{"s.stl", test::stl_ascii(two)}}, 0, "used by 4 triangle(s)"});
    TetMesh overlap = two;
    for (int i = n; i < 2 * n; ++i) overlap.nodes[i] = box.nodes[i - n] + Vec3(0.5, 0.25, 0.25);
    c.push_back(
        {"obj_self_intersecting", {{"s.obj", test::obj_surface(overlap)}}, 0, "intersects itself"});
  }
  c.push_back({"obj_switches_without_p",
               {{"s.obj", test::obj_surface(box)}},
               0,
               "lack 'p'",
               nullptr,
               "q1.4Q"});
  c.push_back({"stl_binary_truncated",
               {{"s.stl", cut(test::stl_binary(box), 0.9)}},
               0,
               "does not match its triangle count"});
  c.push_back({"stl_ascii_quad",
               {{"s.stl",
                 "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 "
                 "0\nvertex 0 1 0\nendloop\n"}},
               7,
               "expected 'endloop'"});
  c.push_back({"stl_short", {{"s.stl", "hello"}}, 0, "too short for a binary STL"});
  c.push_back({"off_header", {{"s.off", "COFF\n0 0 0\n"}}, 1, "not an OFF file"});
  c.push_back({"off_index",
               {{"s.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"}},
               6,
               "vertex index 3 out of range"});
  c.push_back(
      {"off_truncated", {{"s.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n"}}, 5, "unexpected end of file"});
  // ---- dispatch
  c.push_back({"unknown_extension", {{"a.xyz", "1 2 3"}}, 0, "unknown mesh format '.xyz'"});
  c.push_back({"ele_named", {{"a.ele", kEle}}, 0, "name a TetGen mesh by its .node file"});
  return c;
}

TEST(MalformedMeshes, EveryCaseThrowsOneLineNamingFileAndLine) {
  const auto all = cases();
  EXPECT_GE(all.size(), 60u);
  for (const BadCase& c : all) {
    SCOPED_TRACE(c.name);
    TempDir dir;
    for (const File& f : c.files) write_file(dir.file(f.name), f.content);
    MeshReadOptions options;
    options.tetgen_switches = c.switches;
    const std::string msg = test::mesh_error(dir.file(c.files[0].name), options);
    ASSERT_FALSE(msg.empty()) << "loaded without error";
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    const std::string file = dir.file(c.error_name ? c.error_name : c.files[0].name);
    const std::string prefix = c.line > 0 ? file + ":" + std::to_string(c.line) + ": " : file + ":";
    EXPECT_EQ(msg.rfind(prefix, 0), 0u) << msg << "\n  expected prefix: " << prefix;
    EXPECT_NE(msg.find(c.fragment), std::string::npos) << msg << "\n  expected: " << c.fragment;
  }
}

TEST(MalformedMeshes, MissingFile) {
  EXPECT_EQ(test::mesh_error("/nonexistent/a.msh"), "/nonexistent/a.msh: cannot open file");
}

// Random byte edits and truncations of valid files: load or MeshError, nothing else (a crash
// or another exception type fails the test; run under ASan/UBSan for the memory side).
TEST(MalformedMeshes, FuzzedFilesLoadOrThrowMeshError) {
  const TetMesh box = test::small_box();
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"a.msh", test::gmsh_v1(box)},         {"b.msh", test::gmsh_v22(box)},
      {"c.msh", test::gmsh_v41(box)},        {"d.msh", test::gmsh_v22_binary(box)},
      {"e.msh", test::gmsh_v41_binary(box)}, {"f.vtk", test::vtk_ascii(box)},
      {"g.vtk", test::vtk_ascii(box, true)}, {"h.vtk", test::vtk_binary(box, true)},
      {"i.vtu", test::vtu_ascii(box)},       {"j.off", test::off_surface(box)},
      {"k.stl", test::stl_binary(box)}};
  std::mt19937 rng(12345);
  const char interesting[] = {'0', '1', '9', '-', '.',  'e',    ' ', '\n',
                              '$', '<', '>', '"', '\0', '\xff', 'n'};
  TempDir dir;
  int loaded = 0, refused = 0;
  for (const auto& [name, seed] : seeds) {
    for (int iter = 0; iter < 150; ++iter) {
      std::string s = seed;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits && !s.empty(); ++e) {
        const std::size_t at = rng() % s.size();
        switch (rng() % 4) {
          case 0:
            s[at] = static_cast<char>(rng() % 256);
            break;
          case 1:
            s[at] = interesting[rng() % sizeof(interesting)];
            break;
          case 2:
            s.erase(at, 1 + rng() % 8);
            break;
          case 3:
            s.resize(at);
            break;
        }
      }
      const std::string path = write_file(dir.file(name), s);
      try {
        read_mesh(path);
        ++loaded;
      } catch (const MeshError& e) {
        ++refused;
        EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << " iteration " << iter << ": " << e.what();
      }
    }
  }
  EXPECT_GT(refused, 0);
  std::printf("fuzz: %d loaded, %d refused with MeshError\n", loaded, refused);
}

}  // namespace
}  // namespace stc
