// A user's program against an installed mbdae: load a scene, change a parameter, run its
// analyses (a dynamics step), print the last sample. Exit 0 only if the run is ok and its last
// wheel-centre height is finite.
#include <cmath>
#include <cstdio>

#include <mbdae/mbdae.h>
#include <mbdae/version.h>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer SCENE.yaml\n");
    return 1;
  }
  try {
    mbdae::Scene scene = mbdae::load_scene(argv[1]);
    mbdae::set_parameter(scene, "analysis.dynamics.t_end", "0.5");
    const mbdae::Result r = mbdae::run(scene, mbdae::RunOptions{});
    const std::vector<double>& z = r.column("wheel_z");
    std::printf("mbdae %s: %s, %zu samples, wheel_z(%.3f s) = %.9f m\n", MBDAE_VERSION, r.status.c_str(), r.rows(),
                r.column("t").back(), z.back());
    return r.ok() && std::isfinite(z.back()) ? 0 : 3;
  } catch (const mbdae::SceneError& e) {
    for (const auto& m : e.messages) std::fprintf(stderr, "%s\n", m.c_str());
    return 2;
  }
}
