// running_sum — the README tutorial: running sums over a modifiable list, made dynamic.
// Built as an example and run by the tests (it checks itself against a plain loop).
#include <cstdio>
#include <memory>
#include <vector>

#include <sac/sac.hpp>

// The input: a list whose cells hold a modifiable value and a modifiable tail.
struct Cell {
  sac::Mod<long> value;
  sac::Mod<Cell*> next;
};

// The output: one cell per input cell, holding the sum of the values up to it.
struct Out {
  sac::Mod<long> sum;
  sac::Mod<Out*> next;
};

// Ordinary-looking code: write into *dst the running sums of the list starting at c, where
// *before holds the sum of everything before c.
void running_sum(sac::Engine& rt, Cell* c, const sac::Mod<long>* before, sac::Mod<Out*>* dst) {
  if (!c) {
    rt.write(*dst, static_cast<Out*>(nullptr));
    return;
  }
  Out* o = rt.alloc<Out>(c);  // keyed by the input cell: re-executions get the same cell back
  rt.write(*dst, o);
  rt.read(*before, [=](sac::Engine& rt2, long s) {
    rt2.read(c->value, [=](sac::Engine& rt3, long v) { rt3.write(o->sum, s + v); });
  });
  rt.memo_read(c->next, sac::fn<running_sum>(static_cast<const sac::Mod<long>*>(&o->sum), &o->next));
}

std::vector<long> outputs(const sac::Mod<Out*>& head) {
  std::vector<long> v;
  for (Out* o = head.get(); o; o = o->next.get()) v.push_back(o->sum.get());
  return v;
}

std::vector<long> expected(const sac::Mod<Cell*>& head) {
  std::vector<long> v;
  long s = 0;
  for (Cell* c = head.get(); c; c = c->next.get()) v.push_back(s += c->value.get());
  return v;
}

void print(const char* what, const std::vector<long>& v, const sac::Engine& rt) {
  std::printf("%-22s", what);
  for (long x : v) std::printf(" %ld", x);
  std::printf("   (re-executed %llu reads, trace distance %llu)\n",
              static_cast<unsigned long long>(rt.stats().last_reexecuted),
              static_cast<unsigned long long>(rt.stats().last_trace_distance));
}

int main() {
  sac::Engine rt;

  // The mutator builds the input: 3 1 4 1 5 9 2 6.
  std::vector<std::unique_ptr<Cell>> cells;
  for (long v : {3, 1, 4, 1, 5, 9, 2, 6}) {
    cells.push_back(std::make_unique<Cell>());
    rt.set(cells.back()->value, v);
  }
  sac::Mod<Cell*> head;
  sac::Mod<long> zero;
  rt.set(head, cells[0].get());
  rt.set(zero, 0L);
  for (std::size_t i = 0; i < cells.size(); ++i)
    rt.set(cells[i]->next, i + 1 < cells.size() ? cells[i + 1].get() : nullptr);

  // Run once from scratch.
  sac::Mod<Out*> out;
  rt.run([&](sac::Engine& rt2) {
    rt2.memo_read(head, sac::fn<running_sum>(static_cast<const sac::Mod<long>*>(&zero), &out));
  });
  print("from scratch:", outputs(out), rt);
  bool ok = outputs(out) == expected(head);

  // Insert 10 after the second cell: only the sums after it change.
  auto ten = std::make_unique<Cell>();
  rt.set(ten->value, 10L);
  rt.set(ten->next, cells[1]->next.get());
  rt.set(cells[1]->next, ten.get());
  rt.propagate();
  print("insert 10 at 2:", outputs(out), rt);
  ok = ok && outputs(out) == expected(head);

  // A batch of two changes, 4 -> 5 and the next 1 -> 0: one running sum moves, the one after
  // it is equal again, so that write is cut off and nothing further downstream re-runs.
  rt.set(cells[2]->value, 5L);
  rt.set(cells[3]->value, 0L);
  rt.propagate();
  print("4->5 and 1->0:", outputs(out), rt);
  ok = ok && outputs(out) == expected(head);

  // Delete the 10 again.
  rt.set(cells[1]->next, ten->next.get());
  rt.propagate();
  print("delete the 10:", outputs(out), rt);
  ok = ok && outputs(out) == expected(head);

  rt.check_invariants();
  std::printf("%s\n", ok ? "outputs equal a from-scratch computation" : "MISMATCH");
  return ok ? 0 : 1;
}
