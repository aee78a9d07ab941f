// A small writer of VTK's XML PolyData (.vtp) and ParaView data collection (.pvd) files, the
// documented formats of https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html.
// ASCII, every number as the shortest text that reads back as the same double (std::to_chars). Each file is
// written to NAME.tmp and renamed, so a reader never sees a half-written file.
// Why not the VTK library: docs/animation.md ("Writer").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbdae {

// One cell section (Verts, Lines or Polys): cell k has points connectivity[offsets[k-1] ..
// offsets[k]) and the values fields[f][k] of the polydata's cell fields.
struct VtkCells {
  std::vector<int64_t> connectivity, offsets;
  std::vector<std::vector<double>> fields;  // one per PolyData::cell_fields, a value per cell
  size_t size() const { return offsets.size(); }
  void clear();
};

// A named point field with `components` values per point.
struct VtkField {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

struct VtkPolyData {
  std::vector<double> points;            // x y z per point
  std::vector<VtkField> point_fields;    // values for every point
  std::vector<std::string> cell_fields;  // scalar cell fields, values kept in each VtkCells
  VtkCells verts, lines, polys;
  size_t num_points() const { return points.size() / 3; }
  // Empties points, cells and field values, keeping the names and the memory.
  void clear();
};

// Writes `data` to `path` (via path.tmp and a rename). Throws std::runtime_error naming the file.
void write_vtp(const std::string& path, const VtkPolyData& data);

struct PvdEntry {
  double time = 0;
  std::string file;  // relative to the .pvd
};
// Writes a ParaView collection of time steps (via path.tmp and a rename).
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

}  // namespace mbdae
