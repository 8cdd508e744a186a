// sacapps/exptrees.hpp — self-adjusting evaluation of expression trees, and its twin.
//
// Purpose: the value of an arithmetic expression tree (operators +, -, * modulo the prime
// 2^31 - 1, so every intermediate fits in an int64 and results compare exactly; leaves hold
// residues), kept up to date as leaves change value, disappear and come back.
//
// The self-adjusting evaluator follows Acar's "exptrees" (thesis, CMU 2005) and the CEAL
// benchmark of Hammer, Acar and Chen, "CEAL: a C-based language for self-adjusting
// computation", PLDI 2009: each operator node gets two result modifiables (a Partial, keyed
// by the node), evaluates its operands into them with memoized reads of its child
// modifiables, then reads both results and writes the combined value to its destination.
// A changed leaf re-executes the reads on the path to the root and nothing else.
//
// Positions are the leaves, numbered left to right. Structural changes (ExpTree):
//   remove(i)   leaf i leaves the expression. The tree stays as generated; what the
//               computation sees is the generated tree with absent leaves spliced out: an
//               operator with one empty operand is replaced by the other operand, an
//               operator with two empty operands is empty itself, and the empty expression
//               has the value 0. Concretely every operator's child modifiable holds the
//               *representative* of that operand subtree (the subtree itself when both of
//               its operands are non-empty, else the representative of the non-empty one,
//               else null), and the root modifiable holds the root's representative. So
//               removing leaf i replaces i's parent by i's sibling in the grandparent's
//               child modifiable, as expected.
//   reinsert(i) undoes that: the representatives on i's path are restored.
//   set_value(i, v) changes leaf i's value modifiable (present or not).
// The current expression is a function of (shape, leaf values, presence) alone, never of
// the order of the changes, which is what lets a from-scratch run reproduce the trace.
//
// Invariants: after run() or propagate(), *result == evaluate_conventional(shape, present);
// for every operator p and side s, p->child[s] holds rep(operand s of p); root holds
// rep(root); a reachable operator has two non-null children.
// Complexity: from scratch O(n); a leaf change, removal or reinsertion costs O(depth) for
// the mutator and O(depth) trace distance (O(log n) expected for the random trees of
// random_shape, whose depth is that of a random binary search tree).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <sac/sac.hpp>

namespace sacapps::exptrees {

using Value = std::int64_t;

/// The modulus: a prime below 2^31, so a product of two residues fits in an int64.
inline constexpr Value kPrime = 2147483647;

enum class Op : std::uint8_t { Leaf, Add, Sub, Mul };

/// a op b modulo kPrime, for residues a, b in [0, kPrime).
constexpr Value apply(Op op, Value a, Value b) {
  switch (op) {
    case Op::Add: return (a + b) % kPrime;
    case Op::Sub: return (a - b + kPrime) % kPrime;
    case Op::Mul: return (a * b) % kPrime;
    case Op::Leaf: break;
  }
  return 0;
}

/// A node as the computation sees it. Leaves read `value`; operators read `child`.
struct Node {
  explicit Node(Op o) : op(o) {}
  const Op op;
  sac::Mod<Value> value;         // a leaf's value
  sac::Mod<Node*> child[2];      // an operator's operands (their representatives)
};

/// The values of an operator's two operands, allocated by the computation (keyed by node).
struct Partial {
  sac::Mod<Value> operand[2];
};

// ------------------------------------------------------------------ the computation

inline void write_value(sac::Engine& rt, Value v, sac::Mod<Value>* dst) { rt.write(*dst, v); }

inline void combine_right(sac::Engine& rt, Value b, Value a, Op op, sac::Mod<Value>* dst) {
  rt.write(*dst, apply(op, a, b));
}

inline void combine_left(sac::Engine& rt, Value a, Op op, Partial* p, sac::Mod<Value>* dst) {
  rt.read(p->operand[1], sac::fn<&combine_right>(a, op, dst));
}

/// Evaluates the expression x (null = the empty expression, 0) into *dst.
inline void eval(sac::Engine& rt, Node* x, sac::Mod<Value>* dst) {
  if (!x) {
    rt.write(*dst, Value{0});
    return;
  }
  if (x->op == Op::Leaf) {
    rt.read(x->value, sac::fn<&write_value>(dst));
    return;
  }
  Partial* p = rt.alloc<Partial>(x);
  rt.memo_read(x->child[0], sac::fn<&eval>(&p->operand[0]));
  rt.memo_read(x->child[1], sac::fn<&eval>(&p->operand[1]));
  rt.read(p->operand[0], sac::fn<&combine_left>(x->op, p, dst));
}

/// Self-adjusting evaluation (call inside the computation): writes the value of the
/// expression held by root into *result.
inline void eval_tree(sac::Engine& rt, const sac::Mod<Node*>& root, sac::Mod<Value>* result) {
  rt.memo_read(root, sac::fn<&eval>(result));
}

// ------------------------------------------------------------------ the input

/// The generated tree, plain: nodes 0..leaves-1 are the leaves in left-to-right order;
/// each operator comes after both of its operands (post order); the root is the last node.
struct Shape {
  std::size_t leaves = 0;
  std::vector<Op> op;                                   // per node
  std::vector<std::array<std::size_t, 2>> operands;    // per node (operators only)
  std::vector<Value> value;                             // per leaf, in [0, kPrime)
  std::size_t depth = 0;                                // operators on the longest path
};

/// A random tree with `leaves` leaves: the leaf sequence is split at a uniform position,
/// recursively (so the depth is that of a random BST, O(log n) expected); operators and
/// leaf values uniform. A function of (leaves, seed).
Shape random_shape(std::size_t leaves, std::uint64_t seed);

/// Conventional twin: plain recursive evaluation of the expression given by the shape with
/// the absent leaves spliced out (see the top of this file); 0 if nothing is present.
Value evaluate_conventional(const Shape& shape, const std::vector<bool>& present);

/// The mutator-owned input: the nodes and their modifiables, with leaf-wise changes.
class ExpTree {
 public:
  /// Builds the nodes of `shape` in engine e, with leaf i present iff present[i].
  ExpTree(sac::Engine& rt, Shape shape, std::vector<bool> present);
  ExpTree(const ExpTree&) = delete;
  ExpTree& operator=(const ExpTree&) = delete;

  /// The modifiable holding the expression (its root's representative).
  const sac::Mod<Node*>& root() const { return root_; }
  std::size_t leaves() const { return shape_.leaves; }
  bool present(std::size_t leaf) const { return present_.at(leaf); }
  /// Mutator changes (O(depth)); the caller propagates.
  void remove(std::size_t leaf);
  void reinsert(std::size_t leaf);
  void set_value(std::size_t leaf, Value v);

  /// The tree with the current leaf values, and the presence of each leaf.
  const Shape& shape() const { return shape_; }
  const std::vector<bool>& presence() const { return present_; }

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  Node* representative(std::size_t k) const;
  void relink(std::size_t k);

  sac::Engine* rt_;
  Shape shape_;
  std::vector<bool> present_;
  std::vector<std::unique_ptr<Node>> nodes_;
  std::vector<std::size_t> parent_;
  std::vector<Node*> rep_;  // the representative of each node's subtree (null = empty)
  sac::Mod<Node*> root_;
};

}  // namespace sacapps::exptrees
