// GoogleTest main for every anvil test executable: initialises MPI, prints the usual
// report on rank 0 and failures from every rank, and fails on all ranks if any failed.
#include <gtest/gtest.h>

#include <cstdio>

#include "anvil/parallel/comm.hpp"

namespace {

// Prints failed assertions of a rank other than 0, prefixed with the rank.
class RankFailurePrinter : public testing::EmptyTestEventListener {
public:
  explicit RankFailurePrinter(int rank) : rank_(rank) {}
  void OnTestPartResult(const testing::TestPartResult& r) override {
    if (r.failed())
      std::fprintf(stderr, "[rank %d] %s:%d: failure\n%s\n", rank_,
                   r.file_name() ? r.file_name() : "?", r.line_number(), r.summary());
  }

private:
  int rank_;
};

} // namespace

int main(int argc, char** argv) {
  anvil::MpiSession mpi(&argc, &argv);
  testing::InitGoogleTest(&argc, argv);
  const anvil::Comm world = anvil::Comm::world();
  if (world.rank() != 0) {
    auto& listeners = testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new RankFailurePrinter(world.rank()));
  }
  const int rc = RUN_ALL_TESTS();
  return static_cast<int>(world.max(static_cast<std::int64_t>(rc != 0)));
}
