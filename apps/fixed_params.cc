#include "apps/fixed_params.h"

#include <algorithm>
#include <sstream>

namespace puzzlecal {

bool ExpandFixedParams(const std::string& list, CameraModelId model,
                       std::vector<std::string>* names, std::string* error) {
  names->clear();
  const std::vector<std::string> params = CameraModelParamNames(model);
  std::stringstream items(list);
  for (std::string item; std::getline(items, item, ',');) {
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (item.empty()) continue;
    std::vector<std::string> group;
    if (item == "all") {
      group = params;
    } else if (item == "focal") {
      group = {"fx", "fy"};
    } else if (item == "principal-point") {
      group = {"cx", "cy"};
    } else if (item == "distortion") {
      group.assign(params.begin() + 4, params.end());
    } else if (std::find(params.begin(), params.end(), item) != params.end()) {
      group = {item};
    } else {
      std::string known;
      for (const std::string& name : params) known += " " + name;
      *error = "'" + item + "' is not a parameter of " +
               CameraModelName(model) + " (its parameters:" + known +
               "; groups: focal, principal-point, distortion, all)";
      return false;
    }
    AddFixedParams(group, names);
  }
  return true;
}

void AddFixedParams(const std::vector<std::string>& add,
                    std::vector<std::string>* fixed) {
  for (const std::string& name : add) {
    if (std::find(fixed->begin(), fixed->end(), name) == fixed->end()) {
      fixed->push_back(name);
    }
  }
}

}  // namespace puzzlecal
