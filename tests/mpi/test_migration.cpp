// Checks Migration on any rank count: forward() delivers every item of every field type
// (double, int64, a 3-vector struct) to its destination, ordered by source rank then
// source index; reverse() returns every field bit for bit to the original positions
// (NaN payloads and signed zeros included); rebuilding the plan for new destinations
// and moving again reuses its buffers; items staying home and ranks that send or receive
// nothing; a destination out of range throws on every rank; a subset plan moves exactly
// the items its receivers marked.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <vector>

#include "anvil/core/vec3.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/parallel/migration.hpp"

#include "allocation_counter.hpp"

namespace {

using namespace anvil;

std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Arbitrary bit patterns as doubles, including NaNs with payloads, infinities, -0.
double bits_as_double(std::uint64_t b) {
  double d;
  std::memcpy(&d, &b, sizeof d);
  return d;
}

struct Fields {
  std::vector<double> a;
  std::vector<std::int64_t> id; // source rank * 2^32 + source index
  std::vector<Vec3> v;
};

Fields make(int rank, std::size_t n, unsigned seed) {
  Fields f;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t h = mix(seed * 1000003ULL + rank * 7919ULL + i);
    f.a.push_back(i % 7 == 0 ? bits_as_double(0x7ff8dead0000beefULL + i)
                             : (i % 11 == 0 ? -0.0 : bits_as_double(h)));
    f.id.push_back((static_cast<std::int64_t>(rank) << 32) + static_cast<std::int64_t>(i));
    f.v.push_back({static_cast<double>(h % 1000), -static_cast<double>(i), 1.0 / (1 + i)});
  }
  return f;
}

bool same_bits(const void* a, const void* b, std::size_t bytes) {
  return std::memcmp(a, b, bytes) == 0;
}

void round_trip(const Comm& comm, Migration& plan, std::size_t n, unsigned seed,
                int (*dest_of)(std::uint64_t, int, int)) {
  const int P = comm.size(), me = comm.rank();
  const Fields f = make(me, n, seed);
  std::vector<int> dest(n);
  for (std::size_t i = 0; i < n; ++i) dest[i] = dest_of(mix(seed + 31 * i + 17 * me), me, P);
  plan.build(comm, dest);
  ASSERT_EQ(plan.send_count(), n);

  Fields g;
  plan.forward(f.a, g.a);
  plan.forward(f.id, g.id);
  plan.forward(f.v, g.v);
  ASSERT_EQ(g.id.size(), plan.recv_count());

  // Received items: all sent here, ordered by source rank then source index.
  std::vector<std::int64_t> expected(static_cast<std::size_t>(P), 0);
  for (int d : dest) ++expected[static_cast<std::size_t>(d)];
  comm.sum(std::span<std::int64_t>(expected));
  EXPECT_EQ(static_cast<std::int64_t>(plan.recv_count()), expected[static_cast<std::size_t>(me)]);
  for (std::size_t k = 1; k < g.id.size(); ++k) EXPECT_LT(g.id[k - 1], g.id[k]);
  for (int q = 0; q < P; ++q)
    for (std::size_t k = plan.recv_offset(q); k < plan.recv_offset(q) + plan.recv_count(q); ++k)
      EXPECT_EQ(g.id[k] >> 32, q);
  // Each received value is the sender's value for that index (regenerate the sender's).
  for (std::size_t k = 0; k < g.id.size(); ++k) {
    const int src = static_cast<int>(g.id[k] >> 32);
    const auto i = static_cast<std::size_t>(g.id[k] & 0xffffffff);
    const Fields s = make(src, i + 1, seed);
    EXPECT_TRUE(same_bits(&s.a[i], &g.a[k], sizeof(double)));
    EXPECT_TRUE(same_bits(&s.v[i], &g.v[k], sizeof(Vec3)));
  }

  // And back: bit for bit at the original positions.
  Fields h;
  plan.reverse(g.a, h.a);
  plan.reverse(g.id, h.id);
  plan.reverse(g.v, h.v);
  ASSERT_EQ(h.a.size(), n);
  EXPECT_TRUE(same_bits(h.a.data(), f.a.data(), n * sizeof(double)));
  EXPECT_EQ(h.id, f.id);
  EXPECT_TRUE(same_bits(h.v.data(), f.v.data(), n * sizeof(Vec3)));
}

TEST(Migration, RoundTripRandomDestinations) {
  const Comm comm = Comm::world();
  Migration plan;
  round_trip(comm, plan, 1000 + 37 * comm.rank(), 1,
             [](std::uint64_t h, int, int P) { return static_cast<int>(h % P); });
}

TEST(Migration, RebuildReusesThePlan) {
  const Comm comm = Comm::world();
  Migration plan;
  // Shift by one rank, everything home, then everything to rank 0, on the same plan.
  round_trip(comm, plan, 500, 2, [](std::uint64_t, int me, int P) { return (me + 1) % P; });
  round_trip(comm, plan, 700, 3, [](std::uint64_t, int me, int) { return me; });
  round_trip(comm, plan, 300, 4, [](std::uint64_t, int, int) { return 0; });
  round_trip(comm, plan, 1000, 5,
             [](std::uint64_t h, int, int P) { return static_cast<int>(h % P); });
}

// forward_packed() delivers the same bits, in the same layout, as forward() of the items
// it packs.
TEST(Migration, ForwardPackedMatchesForward) {
  const Comm comm = Comm::world();
  const int P = comm.size();
  const std::size_t n = 900 + 13 * static_cast<std::size_t>(comm.rank());
  std::vector<int> dest(n);
  std::vector<Vec3> in(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t h = mix(static_cast<std::uint64_t>(comm.rank()) * 100003 + i);
    dest[i] = static_cast<int>(h % static_cast<std::uint64_t>(P));
    in[i] = {bits_as_double(mix(h)), bits_as_double(mix(h + 1)), bits_as_double(mix(h + 2))};
  }
  Migration plan;
  plan.build(comm, dest);
  std::vector<Vec3> a, b;
  plan.forward(in, a);
  plan.forward_packed(b, [&](std::size_t i, Vec3& item) { item = in[i]; });
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(same_bits(a.data(), b.data(), a.size() * sizeof(Vec3)));
}

// build() with the receive counts given (here from an all-gather of every rank's count())
// makes the plan build() makes: the same layout and bits.
TEST(Migration, BuildWithGivenCountsMatchesBuild) {
  const Comm comm = Comm::world();
  const int P = comm.size();
  const auto Pz = static_cast<std::size_t>(P);
  const std::size_t n = 600 + 31 * static_cast<std::size_t>(comm.rank());
  std::vector<int> dest(n);
  std::vector<Vec3> in(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t h = mix(static_cast<std::uint64_t>(comm.rank()) * 4001 + i);
    dest[i] = static_cast<int>(h % static_cast<std::uint64_t>(P));
    in[i] = {bits_as_double(mix(h)), bits_as_double(mix(h + 1)), bits_as_double(mix(h + 2))};
  }
  std::vector<std::int64_t> mine(Pz), all(Pz * Pz), recv(Pz);
  Migration::count(P, dest, mine);
  comm.allgather_bytes(mine.data(), Pz * sizeof(std::int64_t), all.data());
  for (std::size_t q = 0; q < Pz; ++q)
    recv[q] = all[q * Pz + static_cast<std::size_t>(comm.rank())];
  Migration a_plan, b_plan;
  a_plan.build(comm, dest);
  b_plan.build(comm, dest, recv);
  ASSERT_EQ(a_plan.recv_count(), b_plan.recv_count());
  EXPECT_EQ(a_plan.stays(), b_plan.stays());
  std::vector<Vec3> a, b;
  a_plan.forward(in, a);
  b_plan.forward(in, b);
  EXPECT_TRUE(same_bits(a.data(), b.data(), a.size() * sizeof(Vec3)));
  std::vector<Vec3> back;
  b_plan.reverse(b, back);
  EXPECT_TRUE(same_bits(back.data(), in.data(), in.size() * sizeof(Vec3)));
  // A bad destination: count() marks it, and the given counts make the build throw.
  std::vector<int> bad(dest);
  if (comm.rank() == 0 && !bad.empty()) bad[0] = P;
  Migration::count(P, bad, mine);
  comm.allgather_bytes(mine.data(), Pz * sizeof(std::int64_t), all.data());
  for (std::size_t q = 0; q < Pz; ++q)
    recv[q] = all[q * Pz + static_cast<std::size_t>(comm.rank())];
  Migration c_plan;
  EXPECT_THROW(c_plan.build(comm, bad, recv), std::invalid_argument);
}

// forward_packed() with a stay() callback: the items for other ranks arrive as forward()
// delivers them, each item that stays is reported once, with its received position, and
// its place in the output is left as it was.
TEST(Migration, ForwardPackedReportsTheItemsThatStay) {
  const Comm comm = Comm::world();
  const int P = comm.size();
  const std::size_t n = 800 + 17 * static_cast<std::size_t>(comm.rank());
  std::vector<int> dest(n);
  std::vector<Vec3> in(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t h = mix(static_cast<std::uint64_t>(comm.rank()) * 70001 + i);
    dest[i] = static_cast<int>(h % static_cast<std::uint64_t>(P));
    in[i] = {bits_as_double(mix(h)), bits_as_double(mix(h + 1)), bits_as_double(mix(h + 2))};
  }
  Migration plan;
  plan.build(comm, dest);
  std::vector<Vec3> a;
  plan.forward(in, a);
  const Vec3 untouched{-1.0, -2.0, -3.0};
  std::vector<Vec3> b(a.size(), untouched);
  std::vector<int> stayed(n, 0);
  plan.forward_packed(
      b,
      [&](std::size_t i, Vec3& item) {
        EXPECT_NE(dest[i], comm.rank()) << "packs only items for other ranks";
        item = in[i];
      },
      [&](std::size_t i, std::size_t j) {
        ASSERT_LT(j, a.size());
        EXPECT_EQ(dest[i], comm.rank());
        EXPECT_TRUE(same_bits(&a[j], &in[i], sizeof(Vec3))) << "forward() puts it at j";
        ++stayed[i];
      });
  const std::size_t off = plan.recv_offset(comm.rank()), cnt = plan.recv_count(comm.rank());
  for (std::size_t j = 0; j < a.size(); ++j) {
    if (j >= off && j < off + cnt)
      EXPECT_TRUE(same_bits(&b[j], &untouched, sizeof(Vec3)));
    else
      EXPECT_TRUE(same_bits(&b[j], &a[j], sizeof(Vec3)));
  }
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(stayed[i], dest[i] == comm.rank() ? 1 : 0);
}

// A subset plan (build_subset) moves exactly the items the receivers marked, sent back to
// their senders along reverse(): each arrives with the bits forward() gives it, and
// base_position() says where forward() put it. Marking everything gives forward()'s
// layout; marking nothing moves nothing.
TEST(Migration, SubsetDeliversTheMarkedItems) {
  const Comm comm = Comm::world();
  const int P = comm.size();
  const std::size_t n = 700 + 29 * static_cast<std::size_t>(comm.rank());
  std::vector<int> dest(n);
  std::vector<std::int64_t> in(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t h = mix(static_cast<std::uint64_t>(comm.rank()) * 7919 + i);
    dest[i] = static_cast<int>(h % static_cast<std::uint64_t>(P));
    in[i] = static_cast<std::int64_t>(mix(h + 5) >> 1);
  }
  Migration plan;
  plan.build(comm, dest);
  std::vector<std::int64_t> full;
  plan.forward(in, full);
  for (int rule = 0; rule < 3; ++rule) {
    // The receiver marks its items (about a third, all, none), the senders learn it.
    std::vector<char> recv_keep(full.size()), send_keep;
    for (std::size_t j = 0; j < full.size(); ++j)
      recv_keep[j] = rule == 1 || (rule == 0 && mix(static_cast<std::uint64_t>(full[j])) % 3 == 0);
    plan.reverse(recv_keep, send_keep);
    Migration sub;
    sub.build_subset(plan, send_keep, recv_keep);
    std::size_t marked = 0;
    for (char k : recv_keep) marked += k != 0 ? 1 : 0;
    std::vector<std::int64_t> got;
    sub.forward_packed(got, [&](std::size_t i, std::int64_t& item) {
      EXPECT_NE(send_keep[i], 0) << "packs only marked items";
      item = in[i];
    });
    ASSERT_EQ(got.size(), marked) << "rule " << rule;
    std::size_t last = 0;
    for (std::size_t j = 0; j < got.size(); ++j) {
      const std::size_t pos = sub.base_position(j);
      ASSERT_LT(pos, full.size());
      EXPECT_TRUE(j == 0 || pos > last) << "positions ascend";
      EXPECT_NE(recv_keep[pos], 0);
      EXPECT_EQ(got[j], full[pos]) << "rule " << rule << " item " << j;
      last = pos;
    }
    if (rule == 1)
      for (std::size_t j = 0; j < got.size(); ++j) EXPECT_EQ(sub.base_position(j), j);
  }
}

TEST(Migration, SteadyStateAllocatesNothing) {
  const Comm comm = Comm::world();
  const int P = comm.size();
  std::vector<int> dest(2000);
  for (std::size_t i = 0; i < dest.size(); ++i)
    dest[i] = static_cast<int>(mix(i + 100 * comm.rank()) % P);
  std::vector<double> a(dest.size(), 1.5), back(dest.size());
  std::vector<Vec3> v(dest.size()), vback(dest.size());
  Migration plan;
  plan.build(comm, dest); // grows the plan's arrays and buffers
  std::vector<double> b(plan.recv_count());
  std::vector<Vec3> w(plan.recv_count());
  plan.forward(std::span<const Vec3>(v), std::span<Vec3>(w));
  const std::size_t before = g_allocations;
  for (int cycle = 0; cycle < 5; ++cycle) {
    plan.build(comm, dest);
    plan.forward(std::span<const double>(a), std::span<double>(b));
    plan.forward(std::span<const Vec3>(v), std::span<Vec3>(w));
    plan.reverse(std::span<const double>(b), std::span<double>(back));
    plan.reverse(std::span<const Vec3>(w), std::span<Vec3>(vback));
  }
  EXPECT_EQ(g_allocations, before);
  auto* probe = new std::vector<int>(10); // the counter does count
  EXPECT_GE(g_allocations, before + 2);
  delete probe;
  EXPECT_EQ(back, a);
}

TEST(Migration, EmptyRanks) {
  const Comm comm = Comm::world();
  Migration plan;
  // Only odd ranks hold items; they all go to the last rank.
  const std::size_t n = comm.rank() % 2 == 1 ? 400 : 0;
  round_trip(comm, plan, n, 6, [](std::uint64_t, int, int P) { return P - 1; });
}

TEST(Migration, BadDestinationThrowsEverywhere) {
  const Comm comm = Comm::world();
  Migration plan;
  std::vector<int> dest(10, 0);
  if (comm.rank() == comm.size() - 1) dest[3] = comm.size();
  EXPECT_THROW(plan.build(comm, dest), std::invalid_argument);
}

TEST(Migration, SizeMismatchThrows) {
  const Comm comm = Comm::world();
  Migration plan;
  std::vector<int> dest(5, comm.rank());
  plan.build(comm, dest);
  std::vector<double> in(4), out(5);
  EXPECT_THROW(plan.forward(std::span<const double>(in), std::span<double>(out)),
               std::invalid_argument);
}

} // namespace
