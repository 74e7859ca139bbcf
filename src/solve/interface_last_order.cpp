#include "solve/interface_last_order.hpp"

#include <Eigen/CholmodSupport>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stc {

std::vector<char> dense_rows(const SparseMatrix& a) {
  const int n = static_cast<int>(a.rows());
  const double threshold = std::max(16.0, 10.0 * std::sqrt(static_cast<double>(n)));
  std::vector<char> dense(static_cast<size_t>(n), 0);
  for (int r = 0; r < n; ++r)
    dense[static_cast<size_t>(r)] = a.innerVector(r).nonZeros() > threshold;
  return dense;
}

std::vector<int> order_dense_last(const ColMatrix& upper, const std::vector<char>& dense,
                                  const std::vector<char>& in_frame, cholmod_common& common) {
  const int n = static_cast<int>(upper.rows());
  if (static_cast<int>(dense.size()) != n || static_cast<int>(in_frame.size()) != n)
    throw std::invalid_argument("order_dense_last: one flag per row");
  // The sparse rows' upper triangle, renumbered from 0.
  std::vector<int> index(static_cast<size_t>(n), -1), row_of;
  for (int r = 0; r < n; ++r)
    if (!dense[static_cast<size_t>(r)]) {
      index[static_cast<size_t>(r)] = static_cast<int>(row_of.size());
      row_of.push_back(r);
    }
  const int m = static_cast<int>(row_of.size());
  std::vector<int> order(static_cast<size_t>(m));
  if (m > 0) {
    ColMatrix part(m, m);
    int count = 0;
    for (int c : row_of)
      for (ColMatrix::InnerIterator it(upper, c); it; ++it)
        count += !dense[static_cast<size_t>(it.row())];
    part.resizeNonZeros(count);
    int out = 0;
    for (int k = 0; k < m; ++k) {
      part.outerIndexPtr()[k] = out;
      for (ColMatrix::InnerIterator it(upper, row_of[static_cast<size_t>(k)]); it; ++it)
        if (const int i = index[static_cast<size_t>(it.row())]; i >= 0) {
          part.innerIndexPtr()[out] = i;  // increasing: the renumbering keeps the order
          part.valuePtr()[out++] = it.value();
        }
    }
    part.outerIndexPtr()[m] = out;
    cholmod_sparse view = Eigen::viewAsCholmod(part);
    view.stype = 1;
    std::vector<int> member(static_cast<size_t>(m));
    for (int k = 0; k < m; ++k)
      member[static_cast<size_t>(k)] =
          in_frame[static_cast<size_t>(row_of[static_cast<size_t>(k)])];
    if (!cholmod_camd(&view, nullptr, 0, member.data(), order.data(), &common))
      throw std::runtime_error("framed Cholesky (CHOLMOD): the constrained ordering failed");
  }
  std::vector<int> perm;
  perm.reserve(static_cast<size_t>(n));
  for (const char set : {char{0}, char{1}}) {
    for (int k : order)
      if (const int r = row_of[static_cast<size_t>(k)]; in_frame[static_cast<size_t>(r)] == set)
        perm.push_back(r);
    for (int r = 0; r < n; ++r)
      if (dense[static_cast<size_t>(r)] && in_frame[static_cast<size_t>(r)] == set)
        perm.push_back(r);
  }
  return perm;
}

ColMatrix dense_star_pattern(const ColMatrix& upper, const std::vector<char>& dense, int hub) {
  const int n = static_cast<int>(upper.rows());
  if (static_cast<int>(dense.size()) != n || hub < 0 || hub >= n ||
      !dense[static_cast<size_t>(hub)])
    throw std::invalid_argument("dense_star_pattern: the hub is not a dense row");
  // Column c of the upper triangle holds rows <= c. Entries between two dense rows are
  // dropped and the star written whole instead (whether or not the matrix stores those
  // entries: the star must be complete for the hub to fill the block): the hub's column
  // gets every dense row up to it, every other dense column its diagonal and the hub's row
  // when the hub comes first.
  std::vector<int> rows;
  std::vector<int> outer(static_cast<size_t>(n) + 1, 0), inner;
  inner.reserve(static_cast<size_t>(upper.nonZeros()));
  for (int c = 0; c < n; ++c) {
    rows.clear();
    const bool dense_c = dense[static_cast<size_t>(c)];
    for (ColMatrix::InnerIterator it(upper, c); it; ++it)
      if (!dense_c || !dense[static_cast<size_t>(it.row())])
        rows.push_back(static_cast<int>(it.row()));
    if (dense_c) {
      if (c == hub) {
        for (int r = 0; r <= c; ++r)
          if (dense[static_cast<size_t>(r)]) rows.push_back(r);
      } else {
        if (hub < c) rows.push_back(hub);
        rows.push_back(c);
      }
      std::sort(rows.begin(), rows.end());
    }
    inner.insert(inner.end(), rows.begin(), rows.end());
    outer[static_cast<size_t>(c) + 1] = static_cast<int>(inner.size());
  }
  ColMatrix star(n, n);
  star.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), star.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), star.innerIndexPtr());
  std::fill_n(star.valuePtr(), inner.size(), 1.0);  // a pattern: the values are not read
  return star;
}

}  // namespace stc
