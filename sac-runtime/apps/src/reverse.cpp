// The "reverse" app: sacapps/reverse.hpp behind the uniform App interface.
#include "sacapps/reverse.hpp"

#include "app_support.hpp"

namespace sacapps {
namespace {

class ReverseApp final : public support::ListApp<List<std::int64_t>> {
 public:
  std::string_view name() const override { return "reverse"; }

  void run_conventional() override {
    keep_conventional(reverse::reverse_conventional(plain_input()));
  }

  void run_self_adjusting() override {
    run_from_scratch([](sac::Engine& rt, State& s) {
      reverse::reverse_list(rt, s.input.head(), &s.out);
    });
  }

  bool verify() override {
    drop_stale();
    const State& s = state();
    return s.out.written() &&
           to_vector(s.out) == reverse::reverse_conventional(plain_input()).to_vector();
  }

 protected:
  std::unique_ptr<ListApp> make_empty() const override { return std::make_unique<ReverseApp>(); }
};

}  // namespace

std::unique_ptr<App> make_reverse() { return std::make_unique<ReverseApp>(); }

}  // namespace sacapps
