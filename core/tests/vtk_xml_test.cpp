// The .pvd collection written line by line (PvdAppender) is whole after every line and after a
// failed write. The .vtp files themselves are read back by VTK in cases/tests/test_animation.py.
#include "core/vtk_xml.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace mbdae {
namespace {

std::string read(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string temp_dir(const char* name) {
  const auto dir = std::filesystem::temp_directory_path() / (std::string("mbdae_vtk_xml_") + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

PvdEntry entry(int k) {
  char name[64];
  std::snprintf(name, sizeof name, "animation/frame_%06d.vtp", k);
  return {k / 60.0, name};
}

TEST(PvdAppender, IsTheWholeCollectionAfterEveryLine) {
  const std::string dir = temp_dir("append");
  PvdAppender pvd;
  pvd.open(dir + "/a.pvd");
  std::vector<PvdEntry> entries;
  for (int k = 0; k < 100; ++k) {
    entries.push_back(entry(k));
    pvd.add(entries.back());
    write_pvd(dir + "/b.pvd", entries);
    ASSERT_EQ(read(dir + "/a.pvd"), read(dir + "/b.pvd")) << "after " << k + 1 << " lines";
  }
  pvd.close();
  EXPECT_EQ(read(dir + "/a.pvd"), read(dir + "/b.pvd"));
  std::filesystem::remove_all(dir);
}

TEST(PvdAppender, AFailedLineLeavesTheCollectionOfTheEarlierOnes) {
  const std::string dir = temp_dir("fail");
  PvdAppender pvd;
  pvd.open(dir + "/a.pvd");
  std::vector<PvdEntry> entries;
  // A file size limit of 2000 bytes (SIGXFSZ ignored, so writes fail with EFBIG).
  struct rlimit old;
  getrlimit(RLIMIT_FSIZE, &old);
  const auto handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old;
  small.rlim_cur = 2000;
  setrlimit(RLIMIT_FSIZE, &small);
  std::string error;
  for (int k = 0; k < 100 && error.empty(); ++k) {
    try {
      pvd.add(entry(k));
      entries.push_back(entry(k));
    } catch (const std::runtime_error& e) {
      error = e.what();
    }
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, handler);
  pvd.close();
  EXPECT_NE(error.find("cannot write"), std::string::npos) << error;
  EXPECT_NE(error.find("a.pvd"), std::string::npos) << error;
  ASSERT_GT(entries.size(), 5u);
  ASSERT_LT(entries.size(), 100u);
  write_pvd(dir + "/b.pvd", entries);
  EXPECT_EQ(read(dir + "/a.pvd"), read(dir + "/b.pvd"));
  std::filesystem::remove_all(dir);
}

// vtp_size_bound bounds the file write_vtp writes, for data zlib cannot compress (random
// doubles, the longest ASCII numbers) and for data it can.
TEST(WriteVtp, SizeBoundHoldsForIncompressibleAndCompressibleData) {
  const std::string dir = temp_dir("bound");
  uint64_t state = 12345;
  auto random_double = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return -1.234567890123e-300 * static_cast<double>(state >> 11);
  };
  for (int points : {1, 100, 20000}) {
    for (bool random : {true, false}) {
      VtkPolyData d;
      d.point_fields = {VtkField{"v", 3, {}}};
      d.cell_fields = {"f"};
      for (VtkCells* c : {&d.verts, &d.lines, &d.polys}) c->fields.assign(1, {});
      d.field_data = {{"names", {"a", "bb", std::string(300, 'x')}}};
      for (int k = 0; k < 3 * points; ++k) {
        d.points.push_back(random ? random_double() : 1.0);
        d.point_fields[0].values.push_back(random ? random_double() : 0.0);
      }
      for (int k = 0; k < points; ++k) {
        d.verts.connectivity.push_back(k);
        d.verts.offsets.push_back(k + 1);
        d.verts.fields[0].push_back(random ? random_double() : 2.0);
      }
      for (VtkFormat format : {VtkFormat::kBinary, VtkFormat::kAscii}) {
        const std::string path = dir + "/f.vtp";
        write_vtp(path, d, format);
        EXPECT_LE(std::filesystem::file_size(path), vtp_size_bound(d, format))
            << points << " points, random " << random << ", ascii " << (format == VtkFormat::kAscii);
      }
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mbdae
