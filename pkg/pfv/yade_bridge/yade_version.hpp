// The one YADE build whose object layouts and exported symbols this folder relies on (the
// force container's force_add symbol, the Vector3r and SpherePack storage): Debian's `yade`
// package, yade-double. The Python package refuses to import under another YADE version
// (pfv/_yade_version.py reads this through pfv._core.PINNED_YADE_VERSION), so that a new
// YADE release is met by a deliberate re-check of the layouts, not by reading memory blindly.
#pragma once

namespace pfv {

inline constexpr const char* kPinnedYadeVersion = "2023.02a";

}  // namespace pfv
