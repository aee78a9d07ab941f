#include "core/vtk_xml.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <stdexcept>

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the binary .vtp files are declared LittleEndian");

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

constexpr size_t kBlock = 32768;  // uncompressed bytes per zlib block (VTK's default)
// zlib level and hash memory: docs/formulation.md ("Hand-written pieces and why").
constexpr int kLevel = 1, kMemLevel = 4;

// zlib's worst case for n bytes with window bits 15 and memLevel 4 (deflateBound's bound for
// stored blocks, which it gives when the hash is smaller than the window), with room to spare.
uint64_t deflate_bound(uint64_t n) { return n + (n >> 5) + (n >> 7) + (n >> 11) + 7 + 18; }

}  // namespace

// One zlib stream for every block: compress2() would set up (and clear) a new one per array,
// which cost as much as the compression itself.
struct VtkDeflater {
  z_stream z{};
  VtkDeflater() {
    if (deflateInit2(&z, kLevel, Z_DEFLATED, 15, kMemLevel, Z_DEFAULT_STRATEGY) != Z_OK)
      throw std::runtime_error("zlib cannot start a stream");
  }
  ~VtkDeflater() { deflateEnd(&z); }
  VtkDeflater(const VtkDeflater&) = delete;
  VtkDeflater& operator=(const VtkDeflater&) = delete;
  // Compresses n bytes of src as one zlib stream into out; returns its size.
  size_t pack(const unsigned char* src, size_t n, std::vector<unsigned char>& out) {
    deflateReset(&z);
    const size_t bound = deflateBound(&z, n);
    if (out.size() < bound) out.resize(bound);
    z.next_in = const_cast<Bytef*>(src);
    z.avail_in = static_cast<uInt>(n);
    z.next_out = out.data();
    z.avail_out = static_cast<uInt>(bound);
    if (deflate(&z, Z_FINISH) != Z_STREAM_END) throw std::runtime_error("zlib cannot compress a .vtp array");
    return bound - z.avail_out;
  }
};

namespace {

// A file written under a temporary name and renamed by commit(); removed if not committed.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path) : path_(path), tmp_(path + ".tmp") {
    file_ = std::fopen(tmp_.c_str(), "wb");
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
      const int e = errno;
      std::remove(tmp_.c_str());
      errno = e;
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

// Appends `n` bytes to the appended block as VTK's compressed layout: a header of UInt64
// [blocks, block size, size of the last partial block (0: none), compressed size of each block],
// then the zlib streams. Records where the array starts.
void append_compressed(VtkScratch& s, const void* data, size_t n) {
  s.offsets.push_back(s.appended.size());
  const uint64_t blocks = (n + kBlock - 1) / kBlock;
  const size_t head = s.appended.size();
  s.appended.resize(head + 8 * (3 + blocks));
  const uint64_t first[3] = {blocks, kBlock, n % kBlock};
  std::memcpy(s.appended.data() + head, first, sizeof first);
  const auto* src = static_cast<const unsigned char*>(data);
  if (blocks > 0 && !s.deflater) s.deflater = std::make_shared<VtkDeflater>();
  for (uint64_t b = 0; b < blocks; ++b) {
    const size_t size = std::min(kBlock, n - b * kBlock);
    const size_t packed = s.deflater->pack(src + b * kBlock, size, s.block);
    const uint64_t p = packed;
    std::memcpy(s.appended.data() + head + 8 * (3 + b), &p, 8);
    s.appended.insert(s.appended.end(), s.block.begin(), s.block.begin() + packed);
  }
}

void gather_cell_field(const VtkPolyData& d, size_t k, std::vector<double>& out) {
  out.clear();
  for (const VtkCells* c : {&d.verts, &d.lines, &d.polys}) out.insert(out.end(), c->fields[k].begin(), c->fields[k].end());
}

// Pass 1 of a binary file: every array compressed into the appended block, in file order.
struct Packer {
  VtkScratch& s;
  void doubles(const char*, int, const std::vector<double>& v) { append_compressed(s, v.data(), v.size() * 8); }
  void ints(const char*, const std::vector<int64_t>& v) { append_compressed(s, v.data(), v.size() * 8); }
  void strings(const VtkStrings& a) {  // each string followed by a 0
    s.text.clear();
    for (const auto& v : a.values) s.text.insert(s.text.end(), v.c_str(), v.c_str() + v.size() + 1);
    append_compressed(s, s.text.data(), s.text.size());
  }
  void text(const char*) {}
};

// Pass 2 (or the only pass of an ASCII file): the XML, with the values inline (ASCII) or the
// offsets of pass 1 (binary).
struct Emitter {
  std::FILE* f;
  const VtkScratch* packed;  // null: ASCII
  size_t next = 0;
  const char* format() const { return packed ? "appended" : "ascii"; }
  void open(const char* type, const char* name, int components) {
    std::fprintf(f, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"%s\"", type, name,
                 components, format());
    if (packed) std::fprintf(f, " offset=\"%llu\"/>\n", static_cast<unsigned long long>(packed->offsets[next++]));
    else std::fprintf(f, ">\n");
  }
  void close() { std::fprintf(f, "\n        </DataArray>\n"); }
  void doubles(const char* name, int components, const std::vector<double>& v) {
    open("Float64", name, components);
    if (packed) return;
    char buf[40];
    for (size_t k = 0; k < v.size(); ++k) {
      // The shortest text that reads back as the same double (std::to_chars without a precision).
      char* end = std::to_chars(buf, buf + sizeof buf - 1, v[k]).ptr;
      *end++ = k % 3 == 2 ? '\n' : ' ';
      std::fwrite(buf, 1, end - buf, f);
    }
    close();
  }
  void ints(const char* name, const std::vector<int64_t>& v) {
    open("Int64", name, 1);
    if (packed) return;
    for (int64_t x : v) std::fprintf(f, "%lld ", static_cast<long long>(x));
    close();
  }
  void strings(const VtkStrings& a) {
    std::fprintf(f, "      <Array type=\"String\" Name=\"%s\" NumberOfTuples=\"%zu\" format=\"%s\"", a.name.c_str(),
                 a.values.size(), format());
    if (packed) {
      std::fprintf(f, " offset=\"%llu\"/>\n", static_cast<unsigned long long>(packed->offsets[next++]));
      return;
    }
    std::fprintf(f, ">\n        ");  // ASCII strings: character codes, each string ended by a 0
    for (const auto& v : a.values) {
      for (unsigned char c : v) std::fprintf(f, "%u ", static_cast<unsigned>(c));
      std::fprintf(f, "0 ");
    }
    std::fprintf(f, "\n      </Array>\n");
  }
  void text(const char* s) { std::fputs(s, f); }
};

// Layout: FieldData, Piece { PointData, CellData (verts, then lines, then polys), Points, Verts,
// Lines, Polys }. The visitors see every array in file order.
template <class V>
void visit_field_data(const VtkPolyData& d, V& v) {
  if (d.field_data.empty()) return;
  v.text("    <FieldData>\n");
  for (const auto& s : d.field_data) v.strings(s);
  v.text("    </FieldData>\n");
}

template <class V>
void visit_piece(const VtkPolyData& d, std::vector<double>& gathered, V& v) {
  v.text("      <PointData>\n");
  for (const auto& pf : d.point_fields) v.doubles(pf.name.c_str(), pf.components, pf.values);
  v.text("      </PointData>\n      <CellData>\n");
  for (size_t k = 0; k < d.cell_fields.size(); ++k) {
    gather_cell_field(d, k, gathered);
    v.doubles(d.cell_fields[k].c_str(), 1, gathered);
  }
  v.text("      </CellData>\n      <Points>\n");
  v.doubles("Points", 3, d.points);
  v.text("      </Points>\n");
  const char* open[3] = {"      <Verts>\n", "      <Lines>\n", "      <Polys>\n"};
  const char* close[3] = {"      </Verts>\n", "      </Lines>\n", "      </Polys>\n"};
  const VtkCells* cells[3] = {&d.verts, &d.lines, &d.polys};
  for (int k = 0; k < 3; ++k) {
    v.text(open[k]);
    v.ints("connectivity", cells[k]->connectivity);
    v.ints("offsets", cells[k]->offsets);
    v.text(close[k]);
  }
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

void write_vtp(const std::string& path, const VtkPolyData& d, VtkFormat format, VtkScratch* scratch) {
  check_sizes(d);
  VtkScratch local;
  VtkScratch& s = scratch ? *scratch : local;
  const bool binary = format == VtkFormat::kBinary;
  if (binary) {
    s.appended.clear();
    s.offsets.clear();
    Packer packer{s};
    visit_field_data(d, packer);
    visit_piece(d, s.gathered, packer);
  }
  AtomicFile file(path);
  std::FILE* f = file.get();
  std::fprintf(f, "<?xml version=\"1.0\"?>\n"
                  "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"%s>\n"
                  "  <PolyData>\n",
               binary ? " compressor=\"vtkZLibDataCompressor\"" : "");
  Emitter emitter{f, binary ? &s : nullptr};
  visit_field_data(d, emitter);
  std::fprintf(f, "    <Piece NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" NumberOfLines=\"%zu\" "
                  "NumberOfStrips=\"0\" NumberOfPolys=\"%zu\">\n",
               d.num_points(), d.verts.size(), d.lines.size(), d.polys.size());
  visit_piece(d, s.gathered, emitter);
  std::fprintf(f, "    </Piece>\n  </PolyData>\n");
  if (binary) {
    std::fputs("  <AppendedData encoding=\"raw\">\n   _", f);
    std::fwrite(s.appended.data(), 1, s.appended.size(), f);
    std::fputs("\n  </AppendedData>\n", f);
  }
  std::fputs("</VTKFile>\n", f);
  file.commit();
}

uint64_t vtp_size_bound(const VtkPolyData& d, VtkFormat format) {
  uint64_t numbers = d.points.size(), strings = 0, arrays = 6 + d.field_data.size();
  for (const auto& pf : d.point_fields) numbers += pf.values.size();
  numbers += (d.verts.size() + d.lines.size() + d.polys.size()) * d.cell_fields.size();
  for (const VtkCells* c : {&d.verts, &d.lines, &d.polys}) numbers += c->connectivity.size() + c->offsets.size();
  for (const auto& a : d.field_data)
    for (const auto& v : a.values) strings += v.size() + 1;
  arrays += d.point_fields.size() + d.cell_fields.size() + 1;
  const uint64_t xml = 2048 + 160 * arrays;
  if (format == VtkFormat::kAscii) return xml + 25 * numbers + 4 * strings;
  const uint64_t raw = 8 * numbers + strings;
  return xml + deflate_bound(raw) + arrays * (24 + 8 + 64) + 40 * (raw / kBlock + 1);
}

namespace {

constexpr char kPvdHead[] =
    "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
    "  <Collection>\n";
constexpr char kPvdTail[] = "  </Collection>\n</VTKFile>\n";

int pvd_line(char* buf, size_t size, const PvdEntry& e) {
  return std::snprintf(buf, size, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s\"/>\n", e.time,
                       e.file.c_str());
}

bool write_all(int fd, const char* data, size_t n, uint64_t at) {
  while (n > 0) {
    const ssize_t w = ::pwrite(fd, data, n, static_cast<off_t>(at));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    data += w;
    n -= static_cast<size_t>(w);
    at += static_cast<uint64_t>(w);
  }
  return true;
}

}  // namespace

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  AtomicFile file(path);
  std::FILE* f = file.get();
  std::fputs(kPvdHead, f);
  char line[4200];
  for (const auto& e : entries) {
    const int n = pvd_line(line, sizeof line, e);
    std::fwrite(line, 1, static_cast<size_t>(std::min<int>(n, sizeof line - 1)), f);
  }
  std::fputs(kPvdTail, f);
  file.commit();
}

PvdAppender::~PvdAppender() { close(); }

void PvdAppender::open(std::string path) {
  close();
  path_ = std::move(path);
}

void PvdAppender::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void PvdAppender::add(const PvdEntry& entry) {
  auto fail = [&](const char* what) {
    throw std::runtime_error(std::string(what) + " '" + path_ + "': " + std::strerror(errno));
  };
  if (fd_ < 0) {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) fail("cannot open");
    std::string start = std::string(kPvdHead) + kPvdTail;
    tail_ = sizeof kPvdHead - 1;
    if (!write_all(fd_, start.data(), start.size(), 0)) {
      const int e = errno;
      close();
      ::unlink(path_.c_str());
      errno = e;
      fail("cannot write");
    }
  }
  char buf[4200 + sizeof kPvdTail];
  const int n = pvd_line(buf, 4200, entry);
  if (n < 0 || n >= 4200) throw std::logic_error("PvdAppender: file name too long");
  std::memcpy(buf + n, kPvdTail, sizeof kPvdTail - 1);
  if (!write_all(fd_, buf, n + sizeof kPvdTail - 1, tail_)) {
    // Put the closing tags back where they were: those bytes were on disk before, so this
    // needs no new space (a full disk still leaves a whole collection of the earlier entries).
    const int e = errno;
    write_all(fd_, kPvdTail, sizeof kPvdTail - 1, tail_);
    if (::ftruncate(fd_, static_cast<off_t>(tail_ + sizeof kPvdTail - 1)) != 0) {}
    errno = e;
    fail("cannot write");
  }
  tail_ += static_cast<uint64_t>(n);
}

}  // namespace mbdae
