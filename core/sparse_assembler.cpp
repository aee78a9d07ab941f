#include "core/sparse_assembler.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace mbdae {

void SparseAssembler::begin_pattern(int rows, int cols) {
  recording_ = other_mode_ = true;
  trows_.clear();
  tcols_.clear();
  pattern_ = CscPattern{};
  pattern_.rows = rows;
  pattern_.cols = cols;
}

void SparseAssembler::finalize() {
  const size_t n = trows_.size();
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return tcols_[a] != tcols_[b] ? tcols_[a] < tcols_[b] : trows_[a] < trows_[b];
  });
  calls_.assign(n, Call{0, 0, 0});
  pattern_.colptr.assign(pattern_.cols + 1, 0);
  pattern_.rowind.clear();
  int last_r = -1, last_c = -1;
  for (size_t k = 0; k < n; ++k) {
    const int i = order[k];
    if (trows_[i] != last_r || tcols_[i] != last_c) {
      pattern_.rowind.push_back(trows_[i]);
      pattern_.colptr[tcols_[i] + 1]++;
      last_r = trows_[i];
      last_c = tcols_[i];
    }
    calls_[i] = Call{trows_[i], tcols_[i], static_cast<int>(pattern_.rowind.size()) - 1};
  }
  for (int c = 0; c < pattern_.cols; ++c) pattern_.colptr[c + 1] += pattern_.colptr[c];
  trows_.clear();
  tcols_.clear();
  trows_.shrink_to_fit();
  tcols_.shrink_to_fit();
  recording_ = other_mode_ = false;
}

void SparseAssembler::begin_product(int count, const double* const* x, double* const* out) {
  if (recording_) throw std::logic_error("SparseAssembler: a product pass while recording a pattern");
  other_mode_ = true;
  product_count_ = count;
  product_x_ = x;
  product_out_ = out;
}

void SparseAssembler::end_product() {
  other_mode_ = false;
  product_count_ = 0;
}

void SparseAssembler::record(int row, int col) {
  trows_.push_back(row);
  tcols_.push_back(col);
}

void SparseAssembler::begin_values(double* values) {
  values_ = values;
  cursor_ = 0;
  mismatch_.clear();
  std::fill(values, values + pattern_.nnz(), 0.0);
}

void SparseAssembler::mismatch(int row, int col) {
  if (!mismatch_.empty()) return;  // the first one says it
  mismatch_ = "add() call " + std::to_string(cursor_ + 1) + " of the value pass is at (" +
              std::to_string(row) + ", " + std::to_string(col) + ")";
  if (cursor_ < calls_.size())
    mismatch_ += ", the recorded pattern has (" + std::to_string(calls_[cursor_].row) + ", " +
                 std::to_string(calls_[cursor_].col) + ") there";
  else
    mismatch_ += ", beyond the " + std::to_string(calls_.size()) + " recorded calls";
}

void SparseAssembler::end_values() const {
  if (!mismatch_.empty())
    throw std::logic_error("sparse assembly does not repeat its recorded pattern: " + mismatch_);
  if (cursor_ != calls_.size())
    throw std::logic_error("sparse assembly does not repeat its recorded pattern: " +
                           std::to_string(cursor_) + " add() calls in the value pass, " +
                           std::to_string(calls_.size()) + " recorded");
}

void csc_multiply(const CscPattern& p, const double* values, const double* x, double* y) {
  std::fill(y, y + p.rows, 0.0);
  for (int c = 0; c < p.cols; ++c)
    for (int k = p.colptr[c]; k < p.colptr[c + 1]; ++k) y[p.rowind[k]] += values[k] * x[c];
}

}  // namespace mbdae
