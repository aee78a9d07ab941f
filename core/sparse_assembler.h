// Allocation-free assembly of a sparse matrix with a fixed pattern.
//
// The assembling code is run once in pattern mode: every add(row, col, v) is recorded. Then
// finalize() builds the compressed-column (CSC) pattern, merging duplicates, and a slot table
// mapping the k-th add() call to its position in the value array. In value mode the same code
// (making the same calls in the same order) writes values[slot[k]] += v: no search, no
// allocation. Code that assembles must therefore call add() unconditionally, with zeros where
// a term vanishes. Every value-pass call is checked against the recorded one (a bound and two
// comparisons): a different call is never written anywhere, and end_values() reports it.
#pragma once

#include <cstddef>
#include <string>
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

  // Starts a product pass: the assembling code's add(row, col, v) calls do out[i][row] += v
  // x[i][col] for i < count, a matrix-free product with the matrix that code assembles (no
  // pattern, no values); end_product() ends it.
  void begin_product(int count, const double* const* x, double* const* out);
  void end_product();

  void add(int row, int col, double v) {
    if (other_mode_) {  // recording a pattern or multiplying
      if (recording_) {
        record(row, col);
        return;
      }
      for (int i = 0; i < product_count_; ++i) product_out_[i][row] += v * product_x_[i][col];
      return;
    }
    if (cursor_ < calls_.size() && calls_[cursor_].row == row && calls_[cursor_].col == col) {
      values_[calls_[cursor_++].slot] += v;
      return;
    }
    mismatch(row, col);
  }
  // Whether the last value pass repeated the recorded calls exactly.
  bool complete() const { return mismatch_.empty() && cursor_ == calls_.size(); }
  // Ends a value pass: throws std::logic_error naming the first call that differs from the
  // recorded pattern (a bug of the assembling code), or a pass with too few calls.
  void end_values() const;
  const CscPattern& pattern() const { return pattern_; }

 private:
  struct Call {
    int row, col, slot;  // the recorded add() and its position in the value array
  };
  void mismatch(int row, int col);
  void record(int row, int col);
  bool recording_ = false;
  bool other_mode_ = false;  // recording_ or a product pass
  int product_count_ = 0;
  const double* const* product_x_ = nullptr;
  double* const* product_out_ = nullptr;
  std::vector<int> trows_, tcols_;
  std::vector<Call> calls_;
  std::size_t cursor_ = 0;
  std::string mismatch_;  // the first mismatching call of this value pass
  double* values_ = nullptr;
  CscPattern pattern_;
};

// y = A x for a CSC matrix.
void csc_multiply(const CscPattern& p, const double* values, const double* x, double* y);

}  // namespace mbdae
