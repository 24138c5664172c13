// The renderer's threshold (--mirror-roughness) apart from the GGX code, so that the option table
// (options/options.h) takes its default and floor without the microfacet functions.
#pragma once

namespace pb {

// GGX lobes whose glTF roughness is below the threshold are rendered as perfect mirrors. It may
// not go below kMinMirrorRoughness: roughness 0.032 is alpha 1e-3, which keeps GGX sampling and
// integrals accurate down to grazing cosines of 1e-3 (microfacet.h, kMinGgxAlpha);
// docs/materials.md ("Mirror threshold") says why the default is what it is.
inline constexpr double kMinMirrorRoughness = 0.032;
inline constexpr double kDefaultMirrorRoughness = kMinMirrorRoughness;

}  // namespace pb
