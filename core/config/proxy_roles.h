// What a proxy of real geometry does (config key render.proxies[].roles), with its one name table:
// any subset of hiding virtual objects, catching their shadows, shadowing them, and colliding.
#pragma once

#include <string_view>

namespace arpipe {

struct ProxyRoles {
  bool occlude = true;          // depth only: virtual objects behind it are hidden, the camera shows
  bool receive_shadows = true;  // the differential shadow catcher on its surface
  bool cast_shadows = true;     // joins the shadow map's casters: it shadows the virtual objects
  bool collide = true;          // a static collider of the physics ([render.physics])

  bool operator==(const ProxyRoles&) const = default;
};

// The rule of a roles key: an array of distinct role names (an empty array: none).
struct ProxyRoleNames {};
inline constexpr std::string_view kProxyRoleNames[] = {"occlude", "receive_shadows", "cast_shadows", "collide"};

// The role's flag by its index in kProxyRoleNames.
inline bool& proxy_role(ProxyRoles& roles, size_t index) {
  switch (index) {
    case 0: return roles.occlude;
    case 1: return roles.receive_shadows;
    case 2: return roles.cast_shadows;
    default: return roles.collide;
  }
}

}  // namespace arpipe
