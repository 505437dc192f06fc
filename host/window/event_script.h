// event_script.h — `obscura view --script events.json`: input replayed frame by frame, for tests
// and demos. The file is a JSON list; each entry has "frame" (0-based: it acts before that frame
// renders) and one of
//   "key": "W", "hold": F            the key held for F frames (default 1), pressed at the first
//   "drag": [dx, dy], "button": B     the mouse moved by (dx, dy) pixels with B ("left", "right",
//                                     "middle") held, in that frame
//   "click": [x, y]                   a left click at window pixel (x, y): picks the object there
//   "scroll": s                       wheel steps
//   "panel": {...}                    a panel change (ViewerAction): {"light": N, "scale": s},
//       {"light": N, "color": [r, g, b]}, {"add_light": {point or spot, as relight's edits}},
//       {"remove_light": N}, {"move_light": N, "position": [x, y, z]}, {"select": OBJECT},
//       {"move": OBJECT, "translate": [..]} ("move": "" = the selected object), {"exposure": e},
//       {"aov": NAME}, {"method": "obscurance"|"pathtrace"}, {"rho": "sqrt"|"exp"|"ao"},
//       {"dmax": d}, {"shadow_rays": n}, {"obscurance_rays": n}, {"camera": N}, {"denoise": bool},
//       {"save_view": FILE}, {"load_view": FILE}
//   "window": "resize" (with "size": [w, h]) | "minimize" | "restore" | "close"
//   "screenshot": "out.png"           the frame as shown, after it is presented (panel included
//                                     when --screenshot-ui is given)
// Malformed entries: InputError naming the file and the entry, before any window opens.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "window/glfw_window.h"
#include "window/viewer_action.h"

namespace obscura::window {

struct ScriptEvent {
  enum class Kind { Key, Drag, Click, Scroll, Panel, Window, Screenshot };
  Kind kind = Kind::Key;
  std::size_t frame = 0;
  int key = 0, hold = 1;               // Key (GLFW key code)
  int button = 0;                      // Drag: 0 left, 1 right, 2 middle
  std::array<double, 2> xy{0.0, 0.0};  // Drag: motion; Click: position; Window resize: size
  double scroll = 0.0;
  ViewerAction action;                 // Panel
  std::string text;                    // Window: resize/minimize/restore/close; Screenshot: path
};

class EventScript {
public:
  EventScript() = default;
  explicit EventScript(const std::string& path);

  // Puts frame `frame`'s input into `input` (held keys, drags, clicks, scroll).
  void feed(std::size_t frame, InputState& input) const;
  // The events of `frame` of the other kinds (panel, window, screenshot), in file order.
  std::vector<const ScriptEvent*> eventsAt(std::size_t frame) const;
  bool empty() const { return events_.empty(); }
  // The frames the script spans: one past its last event's frame (a held key's last held frame).
  // `view --offscreen` without --frames runs this many.
  std::size_t length() const;
  const std::vector<ScriptEvent>& events() const { return events_; }

private:
  std::vector<ScriptEvent> events_;
};

} // namespace obscura::window
