// A small writer of VTK's XML PolyData (.vtp) and ParaView data collection (.pvd) files, the
// documented formats of https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html.
// Binary by default: every array in one raw appended block, zlib-compressed in blocks of 32 KiB
// (what vtkXMLPolyDataWriter writes with SetDataModeToAppended, EncodeAppendedDataOff and the
// zlib compressor). ASCII on request: every number as the shortest text that reads back as the
// same double (std::to_chars). Both are exact. Each .vtp is written to NAME.tmp and renamed, so a
// reader never sees a half-written file. Why not the VTK library: docs/formulation.md
// ("Hand-written pieces and why").
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace mbdae {

enum class VtkFormat { kBinary, kAscii };

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

// A named array of strings, written as the dataset's field data (e.g. the names that a cell
// field's numbers stand for).
struct VtkStrings {
  std::string name;
  std::vector<std::string> values;
};

struct VtkPolyData {
  std::vector<double> points;            // x y z per point
  std::vector<VtkField> point_fields;    // values for every point
  std::vector<std::string> cell_fields;  // scalar cell fields, values kept in each VtkCells
  std::vector<VtkStrings> field_data;    // kept by clear()
  VtkCells verts, lines, polys;
  size_t num_points() const { return points.size() / 3; }
  // Empties points, cells and field values, keeping the names, the field data and the memory.
  void clear();
};

struct VtkDeflater;  // a zlib stream kept from array to array (vtk_xml.cpp)

// Buffers a writer reuses from file to file (no allocation once they have grown).
struct VtkScratch {
  std::vector<unsigned char> appended, block, text;
  std::vector<double> gathered;
  std::vector<uint64_t> offsets;
  std::shared_ptr<VtkDeflater> deflater;
};

// Writes `data` to `path` (via path.tmp and a rename). Throws std::runtime_error naming the file.
void write_vtp(const std::string& path, const VtkPolyData& data, VtkFormat format = VtkFormat::kBinary,
               VtkScratch* scratch = nullptr);

// An upper bound of the size in bytes of the file write_vtp writes for `data` (binary: the
// arrays uncompressed plus zlib's worst case; ASCII: 25 characters per number).
uint64_t vtp_size_bound(const VtkPolyData& data, VtkFormat format);

struct PvdEntry {
  double time = 0;
  std::string file;  // relative to the .pvd
};
// Writes a ParaView collection of time steps (via path.tmp and a rename).
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

// A ParaView collection written as its time steps come: the file is created by the first add(),
// and each add() writes one DataSet line over the closing tags and the closing tags after it, so
// the file is a whole collection after every add() and the bytes written grow with the number
// of entries (not its square). A failed add() puts the previous closing tags back and throws.
class PvdAppender {
 public:
  PvdAppender() = default;
  ~PvdAppender();
  PvdAppender(const PvdAppender&) = delete;
  PvdAppender& operator=(const PvdAppender&) = delete;
  void open(std::string path);  // closes any earlier file; nothing written yet
  void add(const PvdEntry& entry);
  void close();

 private:
  std::string path_;
  int fd_ = -1;
  uint64_t tail_ = 0;  // where the closing tags start
};

}  // namespace mbdae
