#include "core/track/tag_family.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>

namespace arpipe {

namespace {

struct FamilyEntry {
  std::string_view name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

// Debian's libapriltag exports the create/destroy pair of every family, and little else.
constexpr FamilyEntry kFamilies[] = {
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag36h10", tag36h10_create, tag36h10_destroy},
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
};

void destroy_nothing(apriltag_family*) {}

}  // namespace

std::vector<std::string_view> tag_family_names() {
  std::vector<std::string_view> names;
  for (const auto& family : kFamilies) names.push_back(family.name);
  return names;
}

std::string joined_tag_family_names() {
  std::string names;
  for (const auto& family : kFamilies) {
    if (!names.empty()) names += ", ";
    names += family.name;
  }
  return names;
}

bool is_tag_family(std::string_view name) {
  for (const auto& family : kFamilies)
    if (family.name == name) return true;
  return false;
}

TagFamilyPtr create_tag_family(std::string_view name) {
  for (const auto& family : kFamilies)
    if (family.name == name) return TagFamilyPtr(family.create(), family.destroy);
  return TagFamilyPtr(nullptr, destroy_nothing);
}

}  // namespace arpipe
