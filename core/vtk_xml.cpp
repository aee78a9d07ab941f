#include "core/vtk_xml.h"

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace mbdae {

void VtkCells::clear() {
  connectivity.clear();
  offsets.clear();
  for (auto& f : fields) f.clear();
}

void VtkPolyData::clear() {
  points.clear();
  for (auto& f : point_fields) f.values.clear();
  verts.clear();
  lines.clear();
  polys.clear();
}

namespace {

// A file written under a temporary name and renamed by commit(); removed if not committed.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path) : path_(path), tmp_(path + ".tmp") {
    file_ = std::fopen(tmp_.c_str(), "w");
    if (!file_) fail("cannot open");
  }
  ~AtomicFile() {
    if (file_) {
      std::fclose(file_);
      std::remove(tmp_.c_str());
    }
  }
  std::FILE* get() const { return file_; }
  void commit() {
    const bool bad = std::ferror(file_) != 0;
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    if (bad || !closed) {
      std::remove(tmp_.c_str());
      fail("cannot write");
    }
    if (std::rename(tmp_.c_str(), path_.c_str()) != 0) fail("cannot rename the temporary file to");
  }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw std::runtime_error(std::string(what) + " '" + path_ + "': " + std::strerror(errno));
  }
  std::string path_, tmp_;
  std::FILE* file_ = nullptr;
};

void write_doubles(std::FILE* f, const std::vector<double>& v, const char* name, int components) {
  std::fprintf(f, "        <DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"ascii\">\n",
               name, components);
  char buf[40];
  for (size_t k = 0; k < v.size(); ++k) {
    // The shortest text that reads back as the same double (std::to_chars without a precision).
    char* end = std::to_chars(buf, buf + sizeof buf - 1, v[k]).ptr;
    *end++ = k % 3 == 2 ? '\n' : ' ';
    std::fwrite(buf, 1, end - buf, f);
  }
  std::fprintf(f, "\n        </DataArray>\n");
}

void write_ints(std::FILE* f, const std::vector<int64_t>& v, const char* name) {
  std::fprintf(f, "        <DataArray type=\"Int64\" Name=\"%s\" format=\"ascii\">\n", name);
  for (size_t k = 0; k < v.size(); ++k) std::fprintf(f, "%lld ", static_cast<long long>(v[k]));
  std::fprintf(f, "\n        </DataArray>\n");
}

void write_cells(std::FILE* f, const char* section, const VtkCells& c) {
  std::fprintf(f, "      <%s>\n", section);
  write_ints(f, c.connectivity, "connectivity");
  write_ints(f, c.offsets, "offsets");
  std::fprintf(f, "      </%s>\n", section);
}

void check_sizes(const VtkPolyData& d) {
  for (const auto& pf : d.point_fields)
    if (pf.values.size() != d.num_points() * pf.components)
      throw std::logic_error("write_vtp: point field '" + pf.name + "' has the wrong size");
  for (const VtkCells* c : {&d.verts, &d.lines, &d.polys}) {
    if (c->fields.size() != d.cell_fields.size()) throw std::logic_error("write_vtp: cell fields missing");
    for (const auto& v : c->fields)
      if (v.size() != c->size()) throw std::logic_error("write_vtp: a cell field has the wrong size");
  }
}

}  // namespace

// Layout: Piece { PointData, CellData (verts, then lines, then polys), Points, Verts, Lines, Polys }.
void write_vtp(const std::string& path, const VtkPolyData& d) {
  check_sizes(d);
  AtomicFile file(path);
  std::FILE* f = file.get();
  std::fprintf(f, "<?xml version=\"1.0\"?>\n"
                  "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                  "  <PolyData>\n"
                  "    <Piece NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" NumberOfLines=\"%zu\" "
                  "NumberOfStrips=\"0\" NumberOfPolys=\"%zu\">\n      <PointData>\n",
               d.num_points(), d.verts.size(), d.lines.size(), d.polys.size());
  for (const auto& pf : d.point_fields) write_doubles(f, pf.values, pf.name.c_str(), pf.components);
  std::fprintf(f, "      </PointData>\n      <CellData>\n");
  std::vector<double> all;
  for (size_t k = 0; k < d.cell_fields.size(); ++k) {
    all.clear();
    for (const VtkCells* c : {&d.verts, &d.lines, &d.polys}) all.insert(all.end(), c->fields[k].begin(), c->fields[k].end());
    write_doubles(f, all, d.cell_fields[k].c_str(), 1);
  }
  std::fprintf(f, "      </CellData>\n      <Points>\n");
  write_doubles(f, d.points, "Points", 3);
  std::fprintf(f, "      </Points>\n");
  write_cells(f, "Verts", d.verts);
  write_cells(f, "Lines", d.lines);
  write_cells(f, "Polys", d.polys);
  std::fprintf(f, "    </Piece>\n  </PolyData>\n</VTKFile>\n");
  file.commit();
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  AtomicFile file(path);
  std::FILE* f = file.get();
  std::fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
                  "  <Collection>\n");
  for (const auto& e : entries)
    std::fprintf(f, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s\"/>\n", e.time, e.file.c_str());
  std::fprintf(f, "  </Collection>\n</VTKFile>\n");
  file.commit();
}

}  // namespace mbdae
