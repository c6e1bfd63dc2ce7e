#include "gfins/app/board.hpp"

namespace gfins::app {

void BoardTable::add(const BoardEntry& e) {
  for (BoardEntry& have : entries_) {
    if (have.kind == e.kind) {
      have = e;
      return;
    }
  }
  entries_.push_back(e);
}

const BoardEntry* BoardTable::find(BoardKind kind) const {
  for (const BoardEntry& e : entries_) {
    if (e.kind == kind) return &e;
  }
  return nullptr;
}

BoardResult make_board(const BoardTable& t, const FwConfig& c) {
  const BoardEntry* e = t.find(c.board);
  if (e == nullptr || e->make == nullptr) {
    BoardResult out;
    out.error = board_not_built(c.board);
    return out;
  }
  return e->make(c);
}

std::string board_not_built(BoardKind kind) {
  return std::string("board.kind = ") + quote_text(to_string(kind)) +
         ": this gfins-fw is built without that board" +
         (kind == BoardKind::kSim ? " (the simulated board is host code: GFINS_SIM_BOARD=OFF)"
                                  : "");
}

}  // namespace gfins::app
