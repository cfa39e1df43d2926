// libapriltag's tag families by name: the project's one list of them, and an owning handle that
// destroys a family with its own destroy function.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

struct apriltag_family;

namespace arpipe {

using TagFamilyPtr = std::unique_ptr<apriltag_family, void (*)(apriltag_family*)>;

std::vector<std::string_view> tag_family_names();
// "tag16h5, tag25h9, ..." for error messages.
std::string joined_tag_family_names();
bool is_tag_family(std::string_view name);
// The family's codes and layout; an empty handle when the name is unknown.
TagFamilyPtr create_tag_family(std::string_view name);

}  // namespace arpipe
