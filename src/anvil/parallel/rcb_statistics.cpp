#include "anvil/parallel/rcb_statistics.hpp"

#include <algorithm>

namespace anvil {

namespace {
nlohmann::json box_json(const Box3& b) {
  return {{"lo", {b.lo.x, b.lo.y, b.lo.z}}, {"hi", {b.hi.x, b.hi.y, b.hi.z}}};
}
} // namespace

nlohmann::json rcb_statistics(const Rcb& rcb) {
  const int P = rcb.ranks();
  const RcbStats& st = rcb.stats();
  const Box3& dom = rcb.domain();
  nlohmann::json counts = nlohmann::json::array(), weights = nlohmann::json::array(),
                 boxes = nlohmann::json::array(), cuts = nlohmann::json::array();
  std::int64_t cmax = 0;
  for (int r = 0; r < P; ++r) {
    counts.push_back(rcb.count(r));
    weights.push_back(rcb.weight(r));
    cmax = std::max(cmax, rcb.count(r));
    Box3 b = rcb.box(r);
    for (int d = 0; d < 3; ++d) {
      b.lo[d] = std::clamp(b.lo[d], dom.lo[d], dom.hi[d]);
      b.hi[d] = std::clamp(b.hi[d], dom.lo[d], dom.hi[d]);
    }
    boxes.push_back(box_json(b));
  }
  for (int m = 1; m < P; ++m) {
    const RcbCut& c = rcb.cuts()[static_cast<std::size_t>(m)];
    nlohmann::json j = {{"split", m}, {"level", c.level}, {"dim", c.dim}, {"value", c.value}};
    j["gid"] = c.gid == RcbCut::kNoTie ? nlohmann::json(nullptr) : nlohmann::json(c.gid);
    cuts.push_back(j);
  }
  const double mean = st.points > 0 ? static_cast<double>(st.points) / P : 0.0;
  return {{"ranks", P},
          {"points", st.points},
          {"counts", counts},
          {"weights", weights},
          {"imbalance", st.imbalance},
          {"count_imbalance", mean > 0 ? static_cast<double>(cmax) / mean : 1.0},
          {"points_moved", st.points_moved},
          {"incremental", st.incremental},
          {"iterations", st.iterations},
          {"total_iterations", st.total_iterations},
          {"domain", box_json(dom)},
          {"boxes", boxes},
          {"cuts", cuts}};
}

} // namespace anvil
