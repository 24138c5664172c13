#include "estimator/channels.h"

namespace pb {

std::string channel_name(Channel id, int component) {
  const ChannelGroup& g = kChannelGroups[size_t(id)];
  if (g.kind == ChannelKind::SCALAR) return std::string(g.name);
  static const char* const rgb[3] = {"R", "G", "B"};
  return (g.name.empty() ? std::string() : std::string(g.name) + ".") + rgb[component];
}

std::vector<std::string> channel_names() {
  std::vector<std::string> names;
  for (const ChannelGroup& g : kChannelGroups)
    for (int c = 0; c < (g.kind == ChannelKind::RGB ? 3 : 1); ++c)
      names.push_back(channel_name(g.id, c));
  return names;
}

}  // namespace pb
