// Allocation-free assembly of a sparse matrix with a fixed pattern.
//
// The assembling code is run once in pattern mode: every add(row, col, v) is recorded. Then
// finalize() builds the compressed-column (CSC) pattern, merging duplicates, and a slot table
// mapping the k-th add() call to its position in the value array. In value mode the same code
// (making the same calls in the same order) writes values[slot[k]] += v: no search, no
// allocation. Code that assembles must therefore call add() unconditionally, with zeros where
// a term vanishes.
#pragma once

#include <cassert>
#include <cstddef>
#include <vector>

namespace mbdae {

struct CscPattern {
  int rows = 0, cols = 0;
  std::vector<int> colptr, rowind;
  int nnz() const { return static_cast<int>(rowind.size()); }
};

class SparseAssembler {
 public:
  // Starts recording a pattern for an n x m matrix.
  void begin_pattern(int rows, int cols);
  // Builds the CSC pattern from the recorded calls.
  void finalize();
  // Starts a value pass writing into `values` (size nnz), which is zeroed.
  void begin_values(double* values);
  bool recording() const { return recording_; }

  void add(int row, int col, double v) {
    if (recording_) {
      trows_.push_back(row);
      tcols_.push_back(col);
      return;
    }
    assert(cursor_ < slot_.size());
    values_[slot_[cursor_++]] += v;
  }
  // Calls made in the last value pass must equal those recorded.
  bool complete() const { return cursor_ == slot_.size(); }
  const CscPattern& pattern() const { return pattern_; }

 private:
  bool recording_ = false;
  std::vector<int> trows_, tcols_, slot_;
  std::size_t cursor_ = 0;
  double* values_ = nullptr;
  CscPattern pattern_;
};

// y = A x for a CSC matrix.
void csc_multiply(const CscPattern& p, const double* values, const double* x, double* y);

}  // namespace mbdae
