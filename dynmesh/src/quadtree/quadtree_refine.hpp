// quadtree_refine.hpp (private) — QuadTreeRefine written as static code on sac-runtime.
//
// Purpose: the program that DynamicQuadtree runs once and then keeps up to date by change
// propagation. It is the seed's Figure 2, with the crowded work queue of each size class
// made explicit and the grading work done depth first by its witness:
//
//   refine(l, C_l):                        C_l: the crowded cells of size class l, FIFO
//     for c in C_l:                          (split_crowded)
//       SPLIT(c); REGRADE(c)
//     for c in C_l:                          (classify, after all of the round's splits)
//       for each child k of c: if k is crowded, append k to C_{l+1}
//     refine(l+1, C_{l+1})
//   REGRADE(c):                            c just split; the witness of what follows
//     for each leaf u of class l−1 touching c (now ill-graded): SPLIT(u); REGRADE(u)
//   SPLIT(c): mark c split; partition c's points among its 2^d children  (split, partition)
//
// Figure 2 queues the ill-graded cells in buckets W_{l−1}, W_{l−2}, ... and empties them
// before class l+1; here each is split as soon as its witness finds it. Both orders finish
// the grading cascade of round l before round l+1 starts and split exactly the cells the
// grading rule forces, so the tree is the same T*; Lemma 2.1/2.2 still hold between rounds
// (a grading split makes no crowded cell and no ill-graded cell below its class). The
// work entries keep Section 4's keys: a crowded entry is keyed by its cell, and a grading
// split lives in its witness's trace and is memoized on (cell, witness). Why not queues
// for grading: ill-graded cells are sparse, and a queue built by destination passing
// re-joins its old trace only at the next appender, which can be thousands of entries on.
//
// How it is made stable (docs/DESIGN.md, "A stable quadtree program"):
//   * cells are named by CellId and found in a directory of slots outside the trace; a slot
//     holds two versioned modifiables, `split` (0 until SPLIT writes 1) and `pts` (the head
//     of the cell's point list), both defaulting to "nothing" (Engine::init_default), so a
//     test of a cell that does not exist yet reads the default and is re-run if it comes to
//     exist earlier in the trace;
//   * SPLIT's partition is a memoized, order-preserving, destination-passing walk over the
//     cell's point list (one memo_read and one write per point; the point's node at the
//     child level is its own, PNode::down, so it needs no keyed allocation), so a new point
//     changes O(1) expected trace per level; a list ends where nothing more is written (its
//     last `next`, or an empty child's `pts`, keeps its null default);
//   * a crowded entry says whether its cell holds two points or one (QNode::two()), which
//     decides its children's tests without looking around (classify): when it holds two,
//     a child's test reads the child's first two list cells; when it holds one, the test
//     reads the cell's list head, and then the list heads of the rest of N(k) for the one
//     child holding the point, until it finds a point;
//   * C_{l+1} is a modifiable list built by destination passing; each walk step is a
//     memo_read keyed by (list cell, tail), so after a change the walk re-joins the old
//     trace at the next cell with a crowded child;
//   * no memo key lets a re-execution reuse a computation far ahead of it in the trace (a
//     memo hit undoes everything between): the partition of a grading split is keyed by
//     its witness, so when an earlier witness takes the split over, it is recomputed (the
//     cell holds at most one point) instead of matched across the trace in between.
// Why the tests read what they read (the invariants the program relies on, all consequences
// of Figure 2's order; the differential tests check the output they imply):
//   * when class l's crowded round tests child k, every point of N(k) lies in a child of a
//     cell of N(c) split in this round: a cell of N(c) (or a larger leaf there) holding a
//     point while k holds one would be crowded, hence in C_l (or split earlier);
//   * a class-(l−1) cell touching a class-l leaf exists (its parent is split), because the
//     tree is graded before each split; so reading its `split` tells leaf from split.
// The level-52 limit is enforced by the mutator before a point enters (two points within
// one grid unit), so the program never splits a level-52 cell.
// Complexity: from scratch O(Σ_points depth + |T*|·3^d) events; per single-point update
// O(lg L/s) expected trace distance.
// Paper: Acar & Hudson, Figure 2, Lemmas 2.1–2.2, Section 4 (keyed appWork, monotonicity);
// Acar, "Self-adjusting computation" (2005) on memo matches and the re-execution window.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <sac/engine.hpp>
#include <sac/fn.hpp>

#include "dynmesh/cell.hpp"
#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

/// A cell of a point list: the located point and the rest of the list. A point has one
/// node per level at which it is partitioned (the input node at level 0); `down` links it
/// to its node one level deeper. The nodes live outside the trace with their point, so the
/// node of (point, level) is always the same object: what a keyed allocation would give,
/// without its hash lookup and its trace event.
template <std::size_t d>
struct PNode {
  explicit PNode(const Position<d>& p) : q(p) {}
  Position<d> q;
  sac::Mod<PNode*> next;
  PNode* down = nullptr;  // the point's node one level deeper (owned by the directory)
};

/// Values of a slot's `split`. QuadTreeRefine writes 0 or kTreeSplit; a postprocess that
/// refines T* further writes later versions (kRefineSplit, or a leaf's mark with the low two
/// bits 0), which QuadTreeRefine's reads, being earlier in the trace, never see.
inline constexpr std::uint8_t kTreeSplit = 1;
inline constexpr std::uint8_t kRefineSplit = 2;
/// Split in T*.
constexpr bool tree_split(std::uint8_t v) noexcept { return (v & 3u) == kTreeSplit; }
/// Split in T* or in a postprocess's refinement of it.
constexpr bool any_split(std::uint8_t v) noexcept { return (v & 3u) != 0; }

/// The 2D slot's stand-in for `kids`.
struct SlotNoKids {};

/// The directory entry of a cell: its versioned state. Lives outside the trace; found by
/// CellId, so identities never depend on when or where a run first named the cell.
template <std::size_t d>
struct Slot {
  explicit Slot(const CellId<d>& c) : key(pack_cell<d>(c)) {}
  CellId<d> id() const noexcept { return unpack_cell<d>(key); }
  PackedCell<d> key;  // its cell, packed (the directory's index reads it)
  sac::Mod<std::uint8_t> split;  // kTreeSplit once SPLIT ran on the cell (see above)
  sac::Mod<PNode<d>*> pts;       // the cell's points (written by its parent's SPLIT)
  /// 3D only: the `split` values of a split cell's eight children, a byte each (child w in
  /// byte w), written by the octree mesh's first walk of T' and read by its second, so that a
  /// leaf's neighbourhood is 27 reads of its parent's neighbours rather than one per cell.
  [[no_unique_address]] std::conditional_t<d == 3, sac::Mod<std::uint64_t>, SlotNoKids> kids;
};

/// A crowded-queue entry's key: its cell, packed, and `two` and `forced` in bits the packing
/// leaves free (bits 52 and 53 of the first word, below the level's byte). 8·d bytes, not
/// 8·d + 16.
template <std::size_t d>
struct QKey {
  static constexpr std::uint64_t kTwo = std::uint64_t{1} << 52;
  static constexpr std::uint64_t kForced = std::uint64_t{1} << 53;
  PackedCell<d> k;
  QKey(const CellId<d>& c, bool two, bool forced = false) : k(pack_cell<d>(c)) {
    k[0] |= (two ? kTwo : 0) | (forced ? kForced : 0);
  }
  bool operator==(const QKey&) const = default;
  std::size_t hash() const noexcept {
    std::uint64_t h = k[0];
    for (std::size_t a = 1; a < d; ++a) h = sac::mix64(h) ^ k[a];
    return static_cast<std::size_t>(sac::mix64(h));
  }
};

/// A crowded-queue entry (C_l), keyed by its QKey, which it also holds.
template <std::size_t d>
struct QNode {
  explicit QNode(const QKey<d>& q) : key(q) {}
  QKey<d> key;
  sac::Mod<QNode*> next;
  CellId<d> cell() const noexcept {
    PackedCell<d> k = key.k;
    k[0] &= ~(QKey<d>::kTwo | QKey<d>::kForced);
    return unpack_cell<d>(k);
  }
  /// The cell holds two or more points; else one, and N(cell) holds another.
  bool two() const noexcept { return (key.k[0] & QKey<d>::kTwo) != 0; }
  /// The cell is split because it is coarser than Refine::split_below, whatever its points.
  bool forced() const noexcept { return (key.k[0] & QKey<d>::kForced) != 0; }
};

/// What the program needs from its owner: the cell directory and the root's point list.
/// `Dir` provides `Slot<d>& get(sac::Engine&, const CellId<d>&)`, creating a slot with
/// default state on first use, and `PNode<d>* below(sac::Engine&, PNode<d>*)`, the point's
/// node one level deeper, created on first use with a null default `next`.
template <std::size_t d, class Dir>
struct Refine {
  using Node = PNode<d>;
  using List = sac::Mod<Node*>;
  using Crowded = sac::Mod<QNode<d>*>;

  Dir* dir;
  List* input;  // the root's list: the input points
  /// Every cell coarser than this level is split, whatever its points (0: T* itself). The
  /// distributed meshes' local programs set it to the partition level, so that a rank's tree,
  /// built from some of the points, has the one-process tree's shape at and below that level
  /// (docs/DISTRIBUTED.md). Fixed before the first run.
  int split_below = 0;

  Slot<d>& slot(sac::Engine& rt, const CellId<d>& c) { return dir->get(rt, c); }

  /// Where SPLIT sends each child's points.
  struct Dests {
    std::array<List*, kChildren<d>> to;
    bool operator==(const Dests&) const = default;
    std::size_t hash() const noexcept {
      std::uint64_t h = 0;
      for (List* m : to) h = sac::hash_combine(h, reinterpret_cast<std::uintptr_t>(m));
      return static_cast<std::size_t>(h);
    }
  };
  static unsigned child_code(const Position<d>& q, int child_level) {
    unsigned w = 0;
    for (std::size_t a = 0; a < d; ++a)
      w |= static_cast<unsigned>((q[a] >> (kMaxLevel - child_level)) & 1u) << a;
    return w;
  }

  // ------------------------------------------------------------------ the program

  /// The program's context (Engine::set_context, which the owner calls before run()):
  /// closures do not carry it.
  static Refine* ctx(sac::Engine& rt) { return rt.context<Refine>(); }

  static void main(sac::Engine& rt) {
    Refine* program = ctx(rt);
    // The root is crowded when it holds two points (its neighbourhood is itself).
    Crowded* c0 = rt.alloc<Crowded>(0);
    if (program->split_below > 0) {
      const QKey<d> key(CellId<d>::root(), false, true);
      QNode<d>* root = rt.alloc<QNode<d>>(key, key);
      rt.write(root->next, nullptr);
      rt.write(*c0, root);
      return rt.memo(sac::fn<&refine>(0, c0));
    }
    rt.read(*program->input, [c0](sac::Engine& rt2, Node* a) {
      if (!a) return rt2.write(*c0, nullptr);
      rt2.read(a->next, [c0](sac::Engine& rt3, Node* b) {
        if (!b) return rt3.write(*c0, nullptr);
        const QKey<d> key(CellId<d>::root(), true);
        QNode<d>* root = rt3.alloc<QNode<d>>(key, key);
        rt3.write(root->next, nullptr);
        rt3.write(*c0, root);
      });
    });
    rt.memo(sac::fn<&refine>(0, c0));
  }

  /// The crowded round of class l (with the grading splits it causes), then class l+1.
  static void refine(sac::Engine& rt, int l, Crowded* cl) {
    rt.read(*cl, [l, cl](sac::Engine& rt2, QNode<d>* head) {
      if (!head) return;  // no crowded cell left: the tree is done
      Crowded* next = rt2.alloc<Crowded>(l + 1);
      rt2.memo_read(*cl, sac::fn<&split_crowded>());
      rt2.memo_read(*cl, sac::fn<&classify>(next));
      rt2.memo(sac::fn<&refine>(l + 1, next));
    });
  }

  /// Step of the first walk over C_l: SPLIT the entry's cell, then the grading splits that
  /// it forces.
  static void split_crowded(sac::Engine& rt, QNode<d>* e) {
    if (!e) return;
    Refine* program = ctx(rt);
    const CellId<d> c = e->cell();
    split(rt, program, c, c);
    regrade(rt, program, c);
    rt.memo_read(e->next, sac::fn<&split_crowded>());
  }

  /// After c split, every leaf one class larger that touches c is ill-graded: split it (c
  /// witnesses it) and, in turn, what that split forces. A leaf that an earlier witness
  /// already split is skipped. c's parent, the first cell touching c, is split (c is a
  /// cell of the tree), so it is not read.
  static void regrade(sac::Engine& rt, Refine* program, const CellId<d>& c) {
    if (c.level == 0) return;
    // The closure holds c packed, with the mask that names u from c in spare index bits
    // (8·d bytes, not 2·8·d): every point makes many of these reads.
    CellId<d> u;
    for (unsigned mask = 1; mask < static_cast<unsigned>(kChildren<d>); ++mask)
      if (coarser_touching_at(c, mask, u))
        rt.read(program->slot(rt, u).split, [packed = pack_with_mask(c, mask)](sac::Engine& rt2, std::uint8_t s) {
          if (s) return;
          unsigned which;
          const CellId<d> witness = unpack_with_mask(packed, which);
          CellId<d> coarser;
          coarser_touching_at(witness, which, coarser);
          split(rt2, ctx(rt2), coarser, witness);
          regrade(rt2, ctx(rt2), coarser);
        });
  }

  /// A cell packed with a coarser-touching mask (< 2^d) in bits 52.. of its last index word,
  /// which indices (< 2^52) leave free (in the first word, below the level's byte).
  static constexpr int kMaskShift = 52;
  static constexpr std::uint64_t kMaskBits = static_cast<std::uint64_t>(kChildren<d> - 1);
  static PackedCell<d> pack_with_mask(const CellId<d>& c, unsigned mask) {
    PackedCell<d> k = pack_cell<d>(c);
    k[d - 1] |= static_cast<std::uint64_t>(mask) << kMaskShift;
    return k;
  }
  static CellId<d> unpack_with_mask(PackedCell<d> k, unsigned& mask) {
    mask = static_cast<unsigned>((k[d - 1] >> kMaskShift) & kMaskBits);
    k[d - 1] &= ~(kMaskBits << kMaskShift);
    return unpack_cell<d>(k);
  }

  /// Figure 2's SPLIT: c becomes split and its points go to its children. The witness (c
  /// itself for a crowded cell) is part of the memo key: when a grading split moves to an
  /// earlier witness, matching the old partition far ahead in the trace would discard all
  /// the trace in between (a memo hit undoes everything up to the entry it reuses).
  static void split(sac::Engine& rt, Refine* program, const CellId<d>& c, const CellId<d>& witness) {
    Slot<d>& cell = program->slot(rt, c);
    rt.write(cell.split, kTreeSplit);
    Dests to;
    for (unsigned w = 0; w < static_cast<unsigned>(kChildren<d>); ++w)
      to.to[w] = &program->slot(rt, child(c, w)).pts;
    List& points = c.level == 0 ? *program->input : cell.pts;
    rt.memo_read(points, sac::fn<&partition>(partition_key(witness, c.level + 1), to));
  }

  /// A partition step's memo key besides its list cell and destinations: the child level
  /// (low 6 bits) and a 58-bit hash of the witness. The witness only keeps a memo match
  /// near its own split; the step computes the same thing whatever it is, so two witnesses
  /// that collide cost stability at worst, never correctness. Hashing it saves 8·d bytes in
  /// each of the partition's records, one per point and level.
  static std::uint64_t partition_key(const CellId<d>& witness, int child_level) {
    return (static_cast<std::uint64_t>(witness.hash()) << 6) | static_cast<std::uint64_t>(child_level);
  }
  static int key_level(std::uint64_t key) { return static_cast<int>(key & 63u); }

  /// One step of the partition (`key`: partition_key()).
  static void partition(sac::Engine& rt, Node* p, std::uint64_t key, Dests to) {
    // The lists end without a write: every destination is a slot's `pts` or a node's
    // `next`, written at most once in a consistent trace and defaulting to null
    // (Engine::init_default), so "null from here on" is what the default already says. A
    // read that sees the default gets a base version then. Writing the 2^d list ends would
    // make most of the versions, and many of them would never be read.
    if (!p) return;
    const unsigned w = child_code(p->q, key_level(key));
    Node* copy = ctx(rt)->dir->below(rt, p);
    rt.write(*to.to[w], copy);
    to.to[w] = &copy->next;
    rt.memo_read(p->next, sac::fn<&partition>(key, to));
  }

  /// Step of the second walk over C_l, after all its splits: queue the crowded children of
  /// the entry's cell. A change that one child's test read re-runs the tests from that child
  /// on; the walk re-joins its old trace at the next entry with a crowded child (the memo
  /// key holds the queue's tail).
  ///
  /// Child k of e's cell c is crowded when it holds two points, or one while a cell of N(k)
  /// holds another; the entry says which of its own cases c is in (QNode::two()):
  ///   * c holds two or more points: every nonempty child is crowded, since a child holding
  ///     one has another point in a sibling, and siblings lie in N(k). Its second list cell
  ///     only tells which case the child's own entry is in.
  ///   * c holds one point: only the child holding it can be crowded, and its siblings are
  ///     empty, so only the rest of N(k) is scanned.
  /// So no test scans a neighbourhood to learn what its parent's entry already says.
  ///   * c is forced (coarser than split_below): its children one level above split_below
  ///     are forced too, with no read; the others are tested in full, siblings included.
  static void classify(sac::Engine& rt, QNode<d>* e, Crowded* out) {
    if (!e) return rt.write(*out, nullptr);
    if (e->forced() && e->cell().level + 1 < ctx(rt)->split_below) return queue_forced(rt, e, out);
    if (e->two() || e->forced()) test_child(rt, ctx(rt), e, 0, out);
    else test_lone(rt, ctx(rt), e, out);
  }
  /// Queues every child of a forced entry whose children are forced as well.
  static void queue_forced(sac::Engine& rt, QNode<d>* e, Crowded* out) {
    for (unsigned w = 0; w < static_cast<unsigned>(kChildren<d>); ++w) {
      const QKey<d> key(child(e->cell(), w), false, true);
      QNode<d>* q = rt.alloc<QNode<d>>(key, key);
      rt.write(*out, q);
      out = &q->next;
    }
    next_entry(rt, e, out);
  }
  /// What follows the test of child w: the next child, or (a lone point's entry, which has
  /// one child to test) the next entry.
  static void after_child(sac::Engine& rt, QNode<d>* e, unsigned w, Crowded* out) {
    if (e->two() || e->forced()) test_child(rt, ctx(rt), e, w + 1, out);
    else next_entry(rt, e, out);
  }
  /// The walk's next step, once e's children are tested.
  static void next_entry(sac::Engine& rt, QNode<d>* e, Crowded* out) {
    rt.memo_read(e->next, sac::fn<&classify>(out));
  }

  /// An entry with the child number and scan position of a test, in one word: a crowding
  /// closure is then 16 bytes, not 24 (about 11 reads per point in 2D). User-space
  /// addresses fit in 48 bits on x86-64 and AArch64 Linux (checked).
  struct At {
    std::uint64_t bits;
    At(QNode<d>* e, unsigned w, int i = 0)
        : bits(reinterpret_cast<std::uintptr_t>(e) | std::uint64_t{w} << 48 |
               static_cast<std::uint64_t>(i) << 56) {
      if (reinterpret_cast<std::uintptr_t>(e) >> 48 != 0) [[unlikely]]
        throw std::logic_error("dynmesh: a heap address above 2^48; crowding closures cannot pack it");
    }
    QNode<d>* e() const { return reinterpret_cast<QNode<d>*>(bits & ((std::uint64_t{1} << 48) - 1)); }
    unsigned w() const { return static_cast<unsigned>((bits >> 48) & 0xffu); }
    int i() const { return static_cast<int>(bits >> 56); }
  };

  /// The tests of e's children (e->two()), one after another: each continues with the
  /// queue's new tail.
  static void test_child(sac::Engine& rt, Refine* program, QNode<d>* e, unsigned w, Crowded* out) {
    if (w == static_cast<unsigned>(kChildren<d>)) return next_entry(rt, e, out);
    rt.read(program->slot(rt, child(e->cell(), w)).pts, [at = At(e, w), out](sac::Engine& rt2, Node* a) {
      if (!a) return test_child(rt2, ctx(rt2), at.e(), at.w() + 1, out);  // empty: not crowded
      rt2.read(a->next, [at, out](sac::Engine& rt3, Node* b) {
        // A forced entry's child holding one point is crowded only if N(k) holds another.
        if (!b && at.e()->forced()) return scan_neighbourhood(rt3, ctx(rt3), at.e(), at.w(), 0, out);
        queue_crowded(rt3, at.e(), at.w(), b != nullptr, out);
      });
    });
  }

  /// e's cell holds one point (!e->two(); never the root): the child holding it is crowded
  /// when a cell of its neighbourhood outside the parent holds a point.
  static void test_lone(sac::Engine& rt, Refine* program, QNode<d>* e, Crowded* out) {
    rt.read(program->slot(rt, e->cell()).pts, [e, out](sac::Engine& rt2, Node* p) {
      // Null only while an update is half propagated: the entry's own test re-runs first.
      if (!p) return next_entry(rt2, e, out);
      const unsigned w = child_code(p->q, e->cell().level + 1);
      scan_neighbourhood(rt2, ctx(rt2), e, w, kChildren<d> - 1, out);  // siblings are empty
    });
  }

  /// The order in which a child with child number w scans N(k) without k, as offset codes
  /// (digit a, base 3, is the offset on axis a plus one, as in for_each_neighbour): its
  /// 2^d − 1 siblings first, by child number, then the rest in code order; test_lone starts
  /// after the siblings. A table, so that a scan step computes one cell, not the whole list.
  static constexpr int kAround = kNeighbourhood<d> - 1;
  static constexpr auto kScanOrder = [] {
    std::array<std::array<int, kAround>, kChildren<d>> order{};
    for (unsigned w = 0; w < static_cast<unsigned>(kChildren<d>); ++w) {
      int n = 0;
      auto sibling = [&](int code) {  // every axis stays inside the parent
        for (std::size_t a = 0; a < d; ++a, code /= 3) {
          const int bit = static_cast<int>((w >> a) & 1u) + code % 3 - 1;
          if (bit < 0 || bit > 1) return false;
        }
        return true;
      };
      for (unsigned v = 0; v < static_cast<unsigned>(kChildren<d>); ++v) {
        if (v == w) continue;
        int code = 0;
        for (std::size_t a = d; a-- > 0;)
          code = code * 3 + static_cast<int>((v >> a) & 1u) - static_cast<int>((w >> a) & 1u) + 1;
        order[w][static_cast<std::size_t>(n++)] = code;
      }
      for (int code = 0; code < kNeighbourhood<d>; ++code)
        if (code != kAround / 2 && !sibling(code)) order[w][static_cast<std::size_t>(n++)] = code;
    }
    return order;
  }();

  /// The cell at offset `code` from k, if it lies in the box.
  static bool offset_cell(const CellId<d>& k, int code, CellId<d>& out) {
    out.level = k.level;
    const std::uint64_t n = cells_per_axis(k.level);
    for (std::size_t a = 0; a < d; ++a, code /= 3) {
      const int off = code % 3 - 1;
      if ((off < 0 && k.index[a] == 0) || (off > 0 && k.index[a] + 1 >= n)) return false;
      out.index[a] = k.index[a] + static_cast<std::uint64_t>(static_cast<std::int64_t>(off));
    }
    return true;
  }

  static void scan_neighbourhood(sac::Engine& rt, Refine* program, QNode<d>* e, unsigned w, int i,
                                 Crowded* out) {
    const CellId<d> k = child(e->cell(), w);
    CellId<d> nb;
    while (i < kAround && !offset_cell(k, kScanOrder[w][static_cast<std::size_t>(i)], nb)) ++i;
    if (i >= kAround) return after_child(rt, e, w, out);
    rt.read(program->slot(rt, nb).pts, [at = At(e, w, i), out](sac::Engine& rt2, Node* p) {
      if (p) return queue_crowded(rt2, at.e(), at.w(), false, out);
      scan_neighbourhood(rt2, ctx(rt2), at.e(), at.w(), at.i() + 1, out);
    });
  }

  /// Queues child w of e's cell, holding two or more points (`two`) or one; then the rest
  /// of e's children (none after a lone point's child).
  static void queue_crowded(sac::Engine& rt, QNode<d>* e, unsigned w, bool two, Crowded* out) {
    const CellId<d> k = child(e->cell(), w);
    const QKey<d> key(k, two);
    QNode<d>* q = rt.alloc<QNode<d>>(key, key);
    rt.write(*out, q);
    after_child(rt, e, w, &q->next);
  }
};

}  // namespace dynmesh::detail
