#include "anvil/contact/contact_phase.hpp"

#include <algorithm>
#include <cmath>

namespace anvil {

ContactPhase::~ContactPhase() = default;

ContactPhase::ContactPhase(const ContactConfig& config, const Mesh& mesh, const FeDecomposition& fe,
                           const std::vector<HexBlock>& blocks, const Comm& comm)
    : config_(config), fe_(fe), comm_(comm), blocks_(blocks), rcb_(comm) {
  global_nodes_ = mesh.num_nodes();
  std::vector<bool> selected(mesh.blocks.size(), config.parts.empty());
  for (const auto& name : config.parts)
    for (std::size_t b = 0; b < mesh.blocks.size(); ++b)
      if (mesh.blocks[b].name == name) selected[b] = true;
  const ExteriorFaces surf = exterior_faces(mesh, selected);
  extra_offset_ = global_nodes_ + static_cast<std::int64_t>(surf.size());

  auto local = [&](std::int64_t gid) {
    const auto it = std::lower_bound(fe.node_gid.begin(), fe.node_gid.end(), gid);
    return (it != fe.node_gid.end() && *it == gid) ? static_cast<int>(it - fe.node_gid.begin())
                                                   : -1;
  };
  for (auto gid : surf.contact_nodes) {
    const int l = local(gid);
    if (l >= 0 && fe.node_owned[l]) my_nodes_.push_back(l);
  }
  // Faces of owned elements, with the penalty stiffness k = scale K A^2 / V and the
  // contact depth fraction V / A of their element, from the initial geometry.
  const auto offsets = mesh.block_offsets();
  for (std::size_t f = 0; f < surf.size(); ++f) {
    const std::int64_t el = surf.element[f];
    const auto b = static_cast<std::size_t>(std::upper_bound(offsets.begin(), offsets.end(), el) -
                                            offsets.begin() - 1);
    const auto& gids = blocks[b].gid;
    const auto it = std::lower_bound(gids.begin(), gids.end(), el);
    if (it == gids.end() || *it != el) continue;
    const auto e = static_cast<std::size_t>(it - gids.begin());
    std::array<int, 4> ln;
    std::array<Vec3, 4> p;
    for (int a = 0; a < 4; ++a) {
      ln[a] = local(surf.nodes[f][a]);
      p[a] = mesh.nodes[surf.nodes[f][a]];
    }
    const double area = 0.5 * norm(cross(p[2] - p[0], p[3] - p[1]));
    const double vol = blocks[b].volume[e];
    const double K = blocks[b].material->elastic().bulk;
    my_face_gid_.push_back(static_cast<std::int64_t>(f));
    my_face_nodes_.push_back(ln);
    std::array<int, 4> opp{};
    int k = 0;
    for (int a = 0; a < 8; ++a)
      if (std::find(hex_faces[surf.side[f]].begin(), hex_faces[surf.side[f]].end(), a) ==
          hex_faces[surf.side[f]].end())
        opp[k++] = blocks[b].conn[a][e];
    my_face_opposite_.push_back(opp);
    my_face_stiffness_.push_back(config.penalty_scale * K * area * area / vol);
    my_face_depth_.push_back(config.depth_fraction * vol / area);
    my_face_element_.emplace_back(el, surf.side[f]);
    my_face_slot_.emplace_back(static_cast<int>(b), static_cast<int>(e));
  }
  my_face_rank_.assign(my_face_gid_.size(), comm.rank());
  // The fields of the items that never change (ids, owners, penalty data), set once.
  node_out_.resize(my_nodes_.size());
  for (std::size_t k = 0; k < my_nodes_.size(); ++k) {
    node_out_[k] = {};
    node_out_[k].gid = fe.node_gid[static_cast<std::size_t>(my_nodes_[k])];
    node_out_[k].owner = comm.rank();
  }
  face_local_.resize(my_face_gid_.size());
  for (std::size_t f = 0; f < face_local_.size(); ++f) {
    auto& it = face_local_[f];
    it = {};
    it.gid = my_face_gid_[f];
    for (int a = 0; a < 4; ++a) {
      const auto l = static_cast<std::size_t>(my_face_nodes_[f][a]);
      it.node[a] = fe.node_gid[l];
      it.owner[a] = fe.node_owner[l];
      it.opposite[a] = fe.node_gid[static_cast<std::size_t>(my_face_opposite_[f][a])];
    }
    it.stiffness = my_face_stiffness_[f];
    it.depth = my_face_depth_[f];
  }
  last_face_.assign(fe.node_gid.size(), -1);
  allowance_.assign(fe.node_gid.size(), 0.0);
  exchange_ = std::make_unique<NodeExchange>(fe, comm);
}

void ContactPhase::set_extra_nodes(std::span<const ContactNodeItem> items) {
  extra_.assign(items.begin(), items.end());
}

void ContactPhase::detect(const ContactNodes& nd, double dt, PhaseTimers& timers) {
  ++stats_.cycles;
  auto predicted = [&](int l, int i) { return nd.x[i][l] + dt * nd.v[i][l]; };

  // Items leaving the FE decomposition: owned contact nodes, faces of owned elements
  // (their constant fields were set at construction). Packing is part of the transfer.
  const std::size_t nf = my_face_gid_.size();
  std::vector<ContactFaceItem>& faces = face_local_;
  {
    ScopedPhase t(timers, Phase::transfer);
    node_out_.resize(my_nodes_.size());
    for (std::size_t k = 0; k < my_nodes_.size(); ++k) {
      const int l = my_nodes_[k];
      auto& it = node_out_[k];
      for (int i = 0; i < 3; ++i) {
        it.x[i] = predicted(l, i);
        it.v[i] = nd.v[i][l];
      }
      it.mass = nd.mass[l];
      it.last_face = last_face_[static_cast<std::size_t>(l)];
      it.allowance = allowance_[static_cast<std::size_t>(l)];
    }
    node_out_.insert(node_out_.end(), extra_.begin(), extra_.end());
    face_centre_.resize(nf);
    for (std::size_t f = 0; f < nf; ++f) {
      auto& it = faces[f];
      for (int a = 0; a < 4; ++a) {
        const int l = my_face_nodes_[f][a];
        for (int i = 0; i < 3; ++i) {
          it.x[a][i] = predicted(l, i);
          it.v[a][i] = nd.v[i][l];
        }
        it.mass[a] = nd.mass[l];
      }
    }
    set_captures(faces, face_centre_);
  }

  // Rebalance: RCB of node positions and face centroids, unit weights.
  if (rebalance_due_) {
    ScopedPhase t(timers, Phase::rebalance);
    const std::size_t np = node_out_.size() + nf;
    px_.resize(np);
    py_.resize(np);
    pz_.resize(np);
    pid_.resize(np);
    for (std::size_t k = 0; k < node_out_.size(); ++k) {
      px_[k] = node_out_[k].x[0];
      py_[k] = node_out_[k].x[1];
      pz_[k] = node_out_[k].x[2];
      pid_[k] = node_out_[k].gid;
    }
    for (std::size_t f = 0; f < nf; ++f) {
      double c[3] = {0, 0, 0};
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < 3; ++i) c[i] += 0.25 * faces[f].x[a][i];
      const std::size_t k = node_out_.size() + f;
      px_[k] = c[0];
      py_[k] = c[1];
      pz_[k] = c[2];
      pid_[k] = global_nodes_ + faces[f].gid;
    }
    const RcbPoints pts{px_, py_, pz_, pid_, {}};
    if (partitioned_)
      rcb_.repartition(pts);
    else
      rcb_.partition(pts);
    partitioned_ = true;
    rebalance_due_ = false;
    ++stats_.rebalances;
  }

  {
    ScopedPhase t(timers, Phase::transfer);
    node_dest_.resize(node_out_.size());
    for (std::size_t k = 0; k < node_out_.size(); ++k)
      node_dest_[k] = rcb_.owner({node_out_[k].x[0], node_out_[k].x[1], node_out_[k].x[2]});
    // Faces go to every rank their capture box touches (ghosts), as copies.
    face_dest_.clear();
    face_src_.clear();
    bool one_copy_each = true; // then copy k is face k
    for (std::size_t f = 0; f < nf; ++f) {
      // Faces of eroded elements have left the surface.
      const auto [fb, fe] = my_face_slot_[f];
      if (blocks_[static_cast<std::size_t>(fb)].alive[static_cast<std::size_t>(fe)] == 0.0) {
        one_copy_each = false;
        continue;
      }
      const auto& fc = faces[f];
      my_face_rank_[f] = rcb_.owner(face_centre_[f]);
      rcb_.overlapping({{fc.lo[0], fc.lo[1], fc.lo[2]}, {fc.hi[0], fc.hi[1], fc.hi[2]}}, ranks_);
      one_copy_each &= ranks_.size() == 1;
      for (int r : ranks_) {
        face_src_.push_back(static_cast<int>(f));
        face_dest_.push_back(r);
      }
    }
    // The plans depend only on the destinations: rebuilt when some rank's have changed
    // (one reduction instead of two all-to-alls of counts).
    const bool changed = !plans_built_ || node_dest_ != node_dest_built_ ||
                         face_dest_ != face_dest_built_ || face_src_ != face_src_built_;
    if (comm_.max(static_cast<std::int64_t>(changed)) != 0) {
      node_plan_.build(comm_, node_dest_);
      face_plan_.build(comm_, face_dest_);
      node_dest_built_ = node_dest_;
      face_dest_built_ = face_dest_;
      face_src_built_ = face_src_;
      plans_built_ = true;
      ++stats_.plan_builds;
    }
    // Where every item stays on this rank, the search reads the local items in place.
    if (node_plan_.stays()) {
      search_nodes_ = &node_out_;
    } else {
      node_plan_.forward(node_out_, node_in_);
      search_nodes_ = &node_in_;
    }
    if (face_plan_.stays() && one_copy_each) {
      search_faces_ = &face_local_;
    } else {
      face_out_.resize(face_src_.size());
      for (std::size_t k = 0; k < face_src_.size(); ++k)
        face_out_[k] = faces[static_cast<std::size_t>(face_src_[k])];
      face_plan_.forward(face_out_, face_in_);
      search_faces_ = &face_in_;
    }
    stats_.bytes_sent += static_cast<double>(node_out_.size() * sizeof(ContactNodeItem) +
                                             face_src_.size() * sizeof(ContactFaceItem));
  }

  {
    ScopedPhase t(timers, Phase::contact_search);
    SearchOptions opt;
    opt.dt = dt;
    find_contacts(*search_nodes_, *search_faces_, opt, search_, pairs_);
    stats_.list_builds = search_.builds;
  }
}

void ContactPhase::forces(const ContactNodes& nd, double dt, PhaseTimers& timers) {
  const std::size_t nn = fe_.node_gid.size();
  for (int i = 0; i < 3; ++i) std::fill(nd.force[i], nd.force[i] + nn, 0.0);
  {
    ScopedPhase t(timers, Phase::contact_force);
    force_out_.clear();
    force_dest_.clear();
    penalty_forces(*search_nodes_, *search_faces_, pairs_, {config_.friction, dt}, force_out_,
                   force_dest_);
    double deepest = 0, resisted = 0;
    for (const auto& p : pairs_) {
      deepest = std::max(deepest, -p.gap);
      resisted = std::max(resisted, -p.gap - p.allowance);
    }
    // Load of this rank: nodes searched plus faces held; one reduction for the balance
    // test, the pair count and the deepest penetrations.
    double red[4] = {static_cast<double>(search_nodes_->size() + search_faces_->size()), 0,
                     static_cast<double>(pairs_.size()), deepest};
    red[1] = red[0];
    double mx[3] = {red[0], red[3], resisted};
    comm_.max(std::span<double>(mx, 3));
    comm_.sum(std::span<double>(red + 1, 2));
    const double mean = red[1] / comm_.size();
    stats_.imbalance = mean > 0 ? mx[0] / mean : 1.0;
    stats_.imbalance_max = std::max(stats_.imbalance_max, stats_.imbalance);
    stats_.pairs = static_cast<std::int64_t>(red[2]);
    stats_.max_penetration = std::max(stats_.max_penetration, mx[1]);
    stats_.max_penetration_resisted = std::max(stats_.max_penetration_resisted, mx[2]);
    rebalance_due_ = stats_.imbalance > config_.rebalance_threshold;
  }

  {
    ScopedPhase t(timers, Phase::transfer);
    force_plan_.build(comm_, force_dest_);
    if (!force_plan_.stays()) force_plan_.forward(force_out_, force_in_);
    stats_.bytes_sent += static_cast<double>(force_out_.size() * sizeof(ContactForceItem));
  }

  {
    ScopedPhase t(timers, Phase::contact_force);
    // Owners add the contributions to each node in ascending (node, pair node): the sum
    // no longer depends on where the pairs were found.
    std::vector<ContactForceItem>& items = force_plan_.stays() ? force_out_ : force_in_;
    std::sort(items.begin(), items.end(), [](const ContactForceItem& a, const ContactForceItem& b) {
      return a.target != b.target ? a.target < b.target : a.slave < b.slave;
    });
    for (int l : my_nodes_) {
      last_face_[static_cast<std::size_t>(l)] = -1;
      allowance_[static_cast<std::size_t>(l)] = 0;
    }
    extra_force_.assign(extra_.size(), {0.0, 0.0, 0.0});
    extra_face_.assign(extra_.size(), -1);
    for (const auto& it : items) {
      if (it.target >= extra_offset_) {
        const auto e = static_cast<std::size_t>(
            std::lower_bound(extra_.begin(), extra_.end(), it.target,
                             [](const ContactNodeItem& a, std::int64_t g) { return a.gid < g; }) -
            extra_.begin());
        for (int i = 0; i < 3; ++i) extra_force_[e][i] += it.f[i];
        if (it.target == it.slave) extra_face_[e] = it.face;
        continue;
      }
      const auto pos = std::lower_bound(fe_.node_gid.begin(), fe_.node_gid.end(), it.target);
      const auto l = static_cast<std::size_t>(pos - fe_.node_gid.begin());
      for (int i = 0; i < 3; ++i) nd.force[i][l] += it.f[i];
      if (it.target == it.slave) {
        last_face_[l] = it.face;
        allowance_[l] = it.allowance;
      }
    }
  }
  {
    ScopedPhase t(timers, Phase::transfer);
    exchange_->from_owners({nd.force[0], nd.force[1], nd.force[2]});
  }
}

std::vector<std::vector<int>>
ContactPhase::element_contact_rank(const std::vector<HexBlock>& blocks) const {
  std::vector<std::vector<int>> out(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b)
    out[b].assign(static_cast<std::size_t>(blocks[b].size()), -1);
  for (std::size_t f = 0; f < my_face_gid_.size(); ++f) {
    const auto [el, side] = my_face_element_[f];
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const auto& g = blocks[b].gid;
      const auto it = std::lower_bound(g.begin(), g.end(), el);
      if (it != g.end() && *it == el) {
        auto& slot = out[b][static_cast<std::size_t>(it - g.begin())];
        if (slot < 0) slot = my_face_rank_[f];
        break;
      }
    }
  }
  return out;
}

} // namespace anvil
