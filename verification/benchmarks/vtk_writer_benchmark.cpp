// mbdae's .vtp writer (core/vtk_xml.h) against VTK's own vtkXMLPolyDataWriter on the same frame,
// both binary appended raw with zlib (and mbdae's ASCII): docs/formulation.md ("Hand-written
// pieces and why"). Built only where libvtk9-dev is installed.
//
//   vtk_writer_benchmark FRAME.vtp MODE N OUTDIR    MODE: mbdae-binary, mbdae-ascii or vtk
//
// Reads FRAME.vtp (a frame mbdae wrote) with VTK's reader, writes it N times to OUTDIR/f_K.vtp and
// prints the bytes per file and the wall time per file. Compare instruction counts with
// `valgrind --tool=callgrind` (the reading is the same in every mode).
#include <vtkAbstractArray.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/vtk_xml.h"

namespace {

void copy_cells(vtkCellArray* from, mbdae::VtkCells& to) {
  for (vtkIdType c = 0; c < from->GetNumberOfCells(); ++c) {
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    from->GetCellAtId(c, n, ids);
    for (vtkIdType k = 0; k < n; ++k) to.connectivity.push_back(ids[k]);
    to.offsets.push_back(static_cast<int64_t>(to.connectivity.size()));
  }
}

// The frame as mbdae's writer takes it: the same points, cells, fields and field data.
mbdae::VtkPolyData convert(vtkPolyData* d) {
  mbdae::VtkPolyData out;
  for (vtkIdType p = 0; p < d->GetNumberOfPoints(); ++p)
    for (int k = 0; k < 3; ++k) out.points.push_back(d->GetPoint(p)[k]);
  for (int a = 0; a < d->GetPointData()->GetNumberOfArrays(); ++a) {
    vtkDataArray* arr = d->GetPointData()->GetArray(a);
    mbdae::VtkField f{arr->GetName(), arr->GetNumberOfComponents(), {}};
    for (vtkIdType t = 0; t < arr->GetNumberOfTuples(); ++t)
      for (int c = 0; c < f.components; ++c) f.values.push_back(arr->GetComponent(t, c));
    out.point_fields.push_back(f);
  }
  copy_cells(d->GetVerts(), out.verts);
  copy_cells(d->GetLines(), out.lines);
  copy_cells(d->GetPolys(), out.polys);
  const vtkIdType nv = d->GetNumberOfVerts(), nl = d->GetNumberOfLines();
  for (int a = 0; a < d->GetCellData()->GetNumberOfArrays(); ++a) {
    vtkDataArray* arr = d->GetCellData()->GetArray(a);
    out.cell_fields.push_back(arr->GetName());
    mbdae::VtkCells* cells[3] = {&out.verts, &out.lines, &out.polys};
    for (auto* cs : cells) cs->fields.resize(out.cell_fields.size());
    for (vtkIdType c = 0; c < arr->GetNumberOfTuples(); ++c)
      cells[c < nv ? 0 : c < nv + nl ? 1 : 2]->fields.back().push_back(arr->GetComponent(c, 0));
  }
  for (int a = 0; a < d->GetFieldData()->GetNumberOfArrays(); ++a) {
    auto* s = vtkStringArray::SafeDownCast(d->GetFieldData()->GetAbstractArray(a));
    if (!s) continue;
    mbdae::VtkStrings names{s->GetName(), {}};
    for (vtkIdType k = 0; k < s->GetNumberOfValues(); ++k) names.values.push_back(s->GetValue(k));
    out.field_data.push_back(names);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s FRAME.vtp mbdae-binary|mbdae-ascii|vtk N OUTDIR\n", argv[0]);
    return 1;
  }
  const std::string mode = argv[2], dir = argv[4];
  const int n = std::stoi(argv[3]);
  std::filesystem::create_directories(dir);
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(argv[1]);
  reader->Update();
  vtkPolyData* frame = reader->GetOutput();
  const mbdae::VtkPolyData data = convert(frame);
  mbdae::VtkScratch scratch;
  auto writer = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToZLib();
  writer->SetHeaderTypeToUInt64();
  writer->SetInputData(frame);
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < n; ++k) {
    const std::string path = dir + "/f_" + std::to_string(k) + ".vtp";
    if (mode == "vtk") {
      writer->SetFileName(path.c_str());
      if (writer->Write() != 1) return 2;
    } else {
      mbdae::write_vtp(path, data, mode == "mbdae-ascii" ? mbdae::VtkFormat::kAscii : mbdae::VtkFormat::kBinary,
                       &scratch);
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %ju bytes per file, %.1f us per file (wall, %d files)\n", mode.c_str(),
              static_cast<uintmax_t>(std::filesystem::file_size(dir + "/f_0.vtp")), 1e6 * seconds / n, n);
  return 0;
}
