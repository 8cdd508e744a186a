// fuzz_edit_reader — libFuzzer target of the edit-script reader (read_edits, dynmesh/io.hpp)
// in 2D and 3D.
//
// Input: the first byte picks the dimension (bit 0: 2 or 3); the rest is the script's text.
// Properties: a read either succeeds or throws InputError (Malformed, NotFinite or Count)
// naming the file and an existing line in a one-line message; a successful read has one
// strictly increasing line number per edit and finite coordinates only, and the edits
// written back read back bit for bit, with whitespace and with ", " / ";" separators.
// Complexity: linear in the input.
#include "fuzz_support.hpp"

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>

#include "dynmesh/edit.hpp"
#include "dynmesh/io.hpp"

namespace {

using namespace dynmesh_fuzz;

template <std::size_t d>
void check_round_trip(const EditScript<d>& script, std::string_view separator) {
  std::string text;
  for (const Edit<d>& e : script.edits) {
    text += e.op == EditOp::Insert ? "+ " : "- ";
    for (std::size_t a = 0; a < d; ++a) text += (a ? std::string(separator) : "") + format_exact(e.point[a]);
    text += '\n';
  }
  std::istringstream in(text);
  const EditScript<d> again = read_edits<d>(in, "again.txt");
  check(again.edits.size() == script.edits.size(), "edits written back read back as a different number of edits");
  for (std::size_t i = 0; i < again.edits.size(); ++i)
    check(again.edits[i].op == script.edits[i].op && same_bits<d>(again.edits[i].point, script.edits[i].point),
          "an edit written back reads back differently");
}

template <std::size_t d>
void fuzz(std::string_view text) {
  const std::string name = "fuzz.edits";
  std::istringstream in{std::string(text)};
  EditScript<d> script;
  try {
    script = read_edits<d>(in, name);
  } catch (const InputError& e) {
    check_reader_error(e, name, text);
    return;
  }
  check(script.name == name, "the script keeps its name");
  check_lines(script.lines, script.edits.size(), text);
  for (const Edit<d>& e : script.edits) {
    check(e.op == EditOp::Insert || e.op == EditOp::Delete, "an edit is neither an insertion nor a deletion");
    check(finite<d>(e.point), "a successful read returned a NaN or infinity");
  }
  check_round_trip<d>(script, " ");
  check_round_trip<d>(script, ", ");
  check_round_trip<d>(script, ";");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  if (data[0] & 1)
    fuzz<3>(text);
  else
    fuzz<2>(text);
  return 0;
}
