// The "sum" app: sacapps/sum.hpp behind the uniform App interface.
#include "sacapps/sum.hpp"

#include "app_support.hpp"

namespace sacapps {
namespace {

class SumApp final : public support::ListApp<sac::Mod<std::int64_t>> {
 public:
  std::string_view name() const override { return "sum"; }

  void run_conventional() override { result_ = sum::sum_conventional(plain_input()); }

  void run_self_adjusting() override {
    run_from_scratch([](sac::Engine& rt, State& s) { sum::sum_list(rt, s.input.head(), &s.out); });
  }

  bool verify() override {
    const State& s = state();
    return s.out.written() && s.out.get() == sum::sum_conventional(plain_input());
  }

 protected:
  std::unique_ptr<ListApp> make_empty() const override { return std::make_unique<SumApp>(); }

 private:
  std::int64_t result_ = 0;
};

}  // namespace

std::unique_ptr<App> make_sum() { return std::make_unique<SumApp>(); }

}  // namespace sacapps
