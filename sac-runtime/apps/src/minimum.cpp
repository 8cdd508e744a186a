// The "minimum" app: sacapps/minimum.hpp behind the uniform App interface.
#include "sacapps/minimum.hpp"

#include "app_support.hpp"

namespace sacapps {
namespace {

class MinimumApp final : public support::ListApp<sac::Mod<std::int64_t>> {
 public:
  std::string_view name() const override { return "minimum"; }

  void run_conventional() override { result_ = minimum::minimum_conventional(plain_input()); }

  void run_self_adjusting() override {
    run_from_scratch([](sac::Engine& rt, State& s) {
      minimum::minimum_list(rt, s.input.head(), &s.out);
    });
  }

  bool verify() override {
    const State& s = state();
    return s.out.written() && s.out.get() == minimum::minimum_conventional(plain_input());
  }

 protected:
  std::unique_ptr<ListApp> make_empty() const override { return std::make_unique<MinimumApp>(); }

 private:
  std::int64_t result_ = 0;
};

}  // namespace

std::unique_ptr<App> make_minimum() { return std::make_unique<MinimumApp>(); }

}  // namespace sacapps
