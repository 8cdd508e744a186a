// The "exptrees" app: sacapps/exptrees.hpp (input generation, the mutator side, the
// conventional twin) behind the uniform App interface.
#include "sacapps/exptrees.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "app_support.hpp"

namespace sacapps::exptrees {

namespace {

struct ShapeBuilder {
  Shape& s;
  std::uint64_t seed;
  std::uint64_t draws = 0;

  std::uint64_t draw() { return sac::mix64(sac::hash_combine(seed, draws++)); }

  // Builds the tree over leaves [lo, hi) and returns its root and depth.
  std::pair<std::size_t, std::size_t> build(std::size_t lo, std::size_t hi) {
    if (hi - lo == 1) return {lo, 0};
    const std::size_t mid = lo + 1 + static_cast<std::size_t>(draw() % (hi - lo - 1));
    const auto [a, da] = build(lo, mid);
    const auto [b, db] = build(mid, hi);
    static constexpr Op kOps[] = {Op::Add, Op::Sub, Op::Mul};
    s.op.push_back(kOps[draw() % 3]);
    s.operands.push_back({a, b});
    return {s.op.size() - 1, 1 + std::max(da, db)};
  }
};

// The value of the subtree of node k with absent leaves spliced out; false if it is empty.
bool eval_plain(const Shape& s, const std::vector<bool>& present, std::size_t k, Value& out) {
  if (k < s.leaves) {
    out = s.value[k];
    return present[k];
  }
  Value a = 0, b = 0;
  const bool ha = eval_plain(s, present, s.operands[k][0], a);
  const bool hb = eval_plain(s, present, s.operands[k][1], b);
  if (ha && hb) out = apply(s.op[k], a, b);
  else if (ha) out = a;
  else if (hb) out = b;
  return ha || hb;
}

}  // namespace

Shape random_shape(std::size_t leaves, std::uint64_t seed) {
  Shape s;
  s.leaves = leaves;
  s.op.assign(leaves, Op::Leaf);
  s.operands.assign(leaves, {0, 0});
  s.value.resize(leaves);
  for (std::size_t i = 0; i < leaves; ++i) s.value[i] = support::draw_value(seed, i) % kPrime;
  if (leaves > 0) {
    ShapeBuilder b{s, sac::mix64(seed ^ 0xe7a3ULL)};
    s.depth = b.build(0, leaves).second;
  }
  return s;
}

Value evaluate_conventional(const Shape& shape, const std::vector<bool>& present) {
  Value v = 0;
  if (shape.leaves == 0 || !eval_plain(shape, present, shape.op.size() - 1, v)) return 0;
  return v;
}

ExpTree::ExpTree(sac::Engine& rt, Shape shape, std::vector<bool> present)
    : rt_(&rt), shape_(std::move(shape)), present_(std::move(present)) {
  const std::size_t n = shape_.op.size();
  if (present_.size() != shape_.leaves) throw std::invalid_argument("ExpTree: presence size");
  nodes_.reserve(n);
  parent_.assign(n, kNone);
  rep_.assign(n, nullptr);
  for (std::size_t k = 0; k < n; ++k) {
    nodes_.push_back(std::make_unique<Node>(shape_.op[k]));
    Node* x = nodes_.back().get();
    if (k < shape_.leaves) {
      rt_->set(x->value, shape_.value[k]);
      rep_[k] = present_[k] ? x : nullptr;
      continue;
    }
    for (int side = 0; side < 2; ++side) {  // operands come first (post order)
      const std::size_t c = shape_.operands[k][side];
      parent_[c] = k;
      rt_->set(x->child[side], rep_[c]);
    }
    rep_[k] = representative(k);
  }
  rt_->set(root_, n ? rep_[n - 1] : nullptr);
}

Node* ExpTree::representative(std::size_t k) const {
  Node* a = rep_[shape_.operands[k][0]];
  Node* b = rep_[shape_.operands[k][1]];
  if (a && b) return nodes_[k].get();
  return a ? a : b;
}

// rep_[k] has changed: store it where k's parent refers to k's subtree, and continue up as
// long as the parent's representative changes too. O(depth).
void ExpTree::relink(std::size_t k) {
  for (;;) {
    const std::size_t p = parent_[k];
    if (p == kNone) {
      rt_->set(root_, rep_[k]);
      return;
    }
    const int side = shape_.operands[p][0] == k ? 0 : 1;
    rt_->set(nodes_[p]->child[side], rep_[k]);
    Node* r = representative(p);
    if (r == rep_[p]) return;
    rep_[p] = r;
    k = p;
  }
}

void ExpTree::remove(std::size_t leaf) {
  if (!present_.at(leaf)) throw std::logic_error("ExpTree::remove: leaf is absent");
  present_[leaf] = false;
  rep_[leaf] = nullptr;
  relink(leaf);
}

void ExpTree::reinsert(std::size_t leaf) {
  if (present_.at(leaf)) throw std::logic_error("ExpTree::reinsert: leaf is present");
  present_[leaf] = true;
  rep_[leaf] = nodes_[leaf].get();
  relink(leaf);
}

void ExpTree::set_value(std::size_t leaf, Value v) {
  shape_.value.at(leaf) = v;
  rt_->set(nodes_[leaf]->value, v);
}

}  // namespace sacapps::exptrees

namespace sacapps {
namespace {

using namespace exptrees;

class ExpTreesApp final : public App {
 public:
  std::string_view name() const override { return "exptrees"; }

  void generate(std::size_t n, std::uint64_t seed) override {
    s_ = std::make_unique<State>(random_shape(n, seed), std::vector<bool>(n, true));
  }

  std::unique_ptr<App> clone_current() const override {
    auto c = std::make_unique<ExpTreesApp>();
    c->s_ = std::make_unique<State>(state().tree.shape(), state().tree.presence());
    return c;
  }

  void run_conventional() override {
    result_ = evaluate_conventional(state().tree.shape(), state().tree.presence());
  }

  void run_self_adjusting() override {
    State& s = state();
    s.rt.run([&](sac::Engine& rt) { eval_tree(rt, s.tree.root(), &s.out); });
  }

  std::size_t positions() const override { return state().tree.leaves(); }
  bool present(std::size_t i) const override { return state().tree.present(i); }
  void remove(std::size_t i) override { state().tree.remove(i); }
  void reinsert(std::size_t i) override { state().tree.reinsert(i); }
  void modify(std::size_t i, std::uint64_t seed) override {
    state().tree.set_value(i, support::draw_value(seed, i) % kPrime);
  }

  bool verify() override {
    const State& s = state();
    return s.out.written() &&
           s.out.get() == evaluate_conventional(s.tree.shape(), s.tree.presence());
  }

  sac::Engine& engine() override { return state().rt; }

 private:
  struct State {
    sac::Engine rt;
    ExpTree tree;
    sac::Mod<Value> out;  // written by the computation
    State(Shape shape, std::vector<bool> present)
        : tree(rt, std::move(shape), std::move(present)) {}
  };

  State& state() {
    if (!s_) throw std::logic_error("exptrees: generate() first");
    return *s_;
  }
  const State& state() const {
    if (!s_) throw std::logic_error("exptrees: generate() first");
    return *s_;
  }

  std::unique_ptr<State> s_;
  Value result_ = 0;
};

}  // namespace

std::unique_ptr<App> make_exptrees() { return std::make_unique<ExpTreesApp>(); }

}  // namespace sacapps
