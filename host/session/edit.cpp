#include "session/edit.h"

namespace obscura::session {

std::string Edit::kindName() const {
  switch (kind) {
    case Kind::Scale: return "scale";
    case Kind::Color: return "color";
    case Kind::AddLight:
    case Kind::AddQuad: return "add_light";
    case Kind::RemoveLight: return "remove_light";
    case Kind::MoveLight: return "move_light";
    case Kind::Move: return "move";
    case Kind::Remove: return "remove";
    case Kind::Insert: return "insert";
  }
  return "?";
}

bool Edit::changesGeometry() const {
  return kind == Kind::AddQuad || kind == Kind::Move || kind == Kind::Remove || kind == Kind::Insert;
}

} // namespace obscura::session
