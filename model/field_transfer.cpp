#include "field_transfer.h"

#include <algorithm>
#include <stdexcept>

namespace polydg {

std::vector<Eigen::VectorXd> transferFields(const DgBasis& from,
                                            const std::vector<const Eigen::VectorXd*>& fields,
                                            const DgBasis& to, const ElementLineage& lineage,
                                            TransferCounts* counts) {
  const Eigen::Index n = to.size(), bs = 3 * n;
  const std::size_t elements = to.numElements();
  std::vector<Eigen::VectorXd> out(fields.size(),
                                   Eigen::VectorXd(static_cast<Eigen::Index>(elements) * bs));
  for (std::size_t e = 0; e < elements; ++e) {
    const std::vector<ElementId> sources = lineage.sources(ElementId(e));
    if (counts) (sources.size() == 1 ? counts->exact : counts->extended) += 1;
    const Eigen::MatrixXd q = transferMatrix(from, sources.front(), to, ElementId(e));
    const Eigen::Index source = static_cast<Eigen::Index>(sources.front().index()) * bs;
    const Eigen::Index target = static_cast<Eigen::Index>(e) * bs;
    for (std::size_t f = 0; f < fields.size(); ++f)
      for (Eigen::Index d = 0; d < 3; ++d)
        out[f].segment(target + d * n, n) = q * fields[f]->segment(source + d * n, n);
  }
  return out;
}

std::vector<Eigen::VectorXd> projectFields(const DgBasis& from,
                                           const std::vector<const Eigen::VectorXd*>& fields,
                                           const DgBasis& to, const ElementLineage& lineage) {
  if (from.kind() != BasisKind::Orthonormal || to.kind() != BasisKind::Orthonormal)
    throw std::invalid_argument("projectFields: the bases must be orthonormal");
  const Eigen::Index n = to.size(), bs = 3 * n;
  const std::size_t elements = to.numElements();
  std::vector<Eigen::VectorXd> out(fields.size(),
                                   Eigen::VectorXd::Zero(static_cast<Eigen::Index>(elements) * bs));
  for (std::size_t e = 0; e < elements; ++e) {
    const Eigen::Index target = static_cast<Eigen::Index>(e) * bs;
    for (ElementId s : lineage.sources(ElementId(e))) {
      const Eigen::MatrixXd q = transferMatrix(to, ElementId(e), from, s);
      const Eigen::Index source = static_cast<Eigen::Index>(s.index()) * bs;
      for (std::size_t f = 0; f < fields.size(); ++f)
        for (Eigen::Index d = 0; d < 3; ++d)
          out[f].segment(target + d * n, n) +=
              q.transpose() * fields[f]->segment(source + d * n, n);
    }
  }
  return out;
}

std::vector<int> levelsAfter(const std::vector<int>& levels, const ElementLineage& lineage,
                             std::size_t elements,
                             const std::unordered_set<std::uint32_t>& refined) {
  std::vector<int> out(elements, 0);
  for (std::size_t e = 0; e < elements; ++e)
    for (ElementId source : lineage.sources(ElementId(e)))
      out[e] = std::max(out[e], levels[source.index()] + (refined.count(source.value) ? 1 : 0));
  return out;
}

}  // namespace polydg
