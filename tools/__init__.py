"""photonbound's Python tools, one package run from the repository root with python3 -m.

  python3 -m tools.make_scenes     the glTF scenes in scenes/ (standard library only)
  python3 -m tools.make_corpus     glTF files laid out as Blender's exporter writes them
  python3 -m tools.make_sky        an equirectangular sky map (EXR)
  python3 -m tools.reference       reference images: analytic answers and long renders
  python3 -m tools.study           the speed-accuracy study
  python3 -m tools.views           PNG views of a photonbound EXR
  python3 -m tools.plot_logs       plots of convergence logs and of a sweep of targets
  python3 -m tools.hostile         the hostile corpus: each class of issue 36, run with limits
  python3 -m tools.adaptive_study  passes and seconds to a target per --adaptive mode
  python3 -m tools.mitsuba_side_by_side
                                   relative error against seconds beside Mitsuba 3 (the peer
                                   installed from PyPI when it runs, into a venv of its own;
                                   tools/mitsuba_peer.py runs there; never in CI)
  python3 -m tools.cycles_side_by_side
                                   a render beside Blender's Cycles from the same view, lights
                                   and sky (Blender from Debian when it runs; never in CI)

Each takes --help. The modules they share, one job each, so that every tool does it the same
way:

  common       ToolError (a one-line, user-facing failure), run_main, atomic file writes
  gltf_scene   the glTF reader (standard library only)
  gltf_writer  the glTF writer: one binary buffer, .gltf (embedded or external) and .glb
  exr          photonbound's EXR channel layout (src/estimator/channels.def), reading and
               writing EXRs
  cli          how the tools run build/photonbound and read its logs
  analytic     the closed-form answers of the analytic scenes

Runs under /usr/bin/python3 with the Debian packages python3-numpy, python3-matplotlib and
python3-openimageio (tools/install-deps.sh); make_scenes and gltf_scene need none of them.
"""
