// The EXR channel layout, from channels.def (the one table of it).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace pb {

enum class ChannelKind { RGB, SCALAR };

enum class Channel {
#define PB_CHANNEL(id, name, kind, meaning) id,
#include "estimator/channels.def"
#undef PB_CHANNEL
};

struct ChannelGroup {
  Channel id;
  std::string_view name;  // "" for the radiance
  ChannelKind kind;
  std::string_view meaning;
};

inline constexpr ChannelGroup kChannelGroups[] = {
#define PB_CHANNEL(id, name, kind, meaning) {Channel::id, name, ChannelKind::kind, meaning},
#include "estimator/channels.def"
#undef PB_CHANNEL
};

// "R", "G", "B" for the radiance, "ErrorBound.R" ... for the others; `component` is 0..2 for an
// RGB group and ignored for a scalar one.
std::string channel_name(Channel id, int component = 0);

// Every channel name in file order.
std::vector<std::string> channel_names();

}  // namespace pb
