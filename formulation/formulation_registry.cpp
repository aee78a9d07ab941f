#include "formulation/formulation_registry.h"

#include "formulation/ggl_dae.h"
#include "formulation/index1_dae.h"
#include "formulation/index3_dae.h"

namespace mbdae {
namespace {

// The factories an entry and its no-handover twin share (the same DAE; only formulation_at tells
// them apart).
std::unique_ptr<MultibodyDae> make_index3(const System& s, const FormulationParameters& p) {
  return std::make_unique<Index3Dae>(s, p.constraint_scale, true);
}

std::unique_ptr<MultibodyDae> make_index1(const System& s, const FormulationParameters& p) {
  return std::make_unique<Index1Dae>(s, p.constraint_scale, BaumgarteParameters{p.baumgarte_alpha, p.baumgarte_beta},
                                     false, 0.0);
}

}  // namespace

const std::vector<Formulation>& formulation_registry() {
  static const std::vector<Formulation> table = {
      {"index3", "index-3 DAE: positions, velocities, multipliers (formulation/index3_dae.h)", true, false,
       &make_index3},
      {"index3-no-handover",
       "index3 at every rtol, also below 1e-6 where index3 runs as index2-ggl (formulation/index3_dae.h)", true,
       false,
       &make_index3},
      {"index3-positions",
       "index-3 DAE with the error test on positions per step only, the former default (formulation/index3_dae.h)",
       true, false,
       [](const System& s, const FormulationParameters& p) -> std::unique_ptr<MultibodyDae> {
         return std::make_unique<Index3Dae>(s, p.constraint_scale, false);
       }},
      {"index2-ggl", "stabilized index 2, Gear-Gupta-Leimkuhler (formulation/ggl_dae.h)", false, false,
       [](const System& s, const FormulationParameters& p) -> std::unique_ptr<MultibodyDae> {
         return std::make_unique<GglDae>(s, p.constraint_scale);
       }},
      {"index1", "index 1 with Baumgarte stabilization (formulation/index1_dae.h)", false, false,
       &make_index1, true, 1.0},
      {"index1-no-handover",
       "index1 at every rtol, also below 1e-9 where index1 runs as index2-ggl (formulation/index1_dae.h)", false,
       false,
       &make_index1, true, 1.0},
      {"penalty", "index 1 with a penalty term and Baumgarte stabilization (formulation/index1_dae.h)", false, true,
       [](const System& s, const FormulationParameters& p) -> std::unique_ptr<MultibodyDae> {
         return std::make_unique<Index1Dae>(s, p.constraint_scale,
                                            BaumgarteParameters{p.baumgarte_alpha, p.baumgarte_beta}, false, p.penalty);
       },
       true, 5.0},
  };
  return table;
}

const Formulation* find_formulation(const std::string& name) {
  for (const Formulation& f : formulation_registry())
    if (f.name == name) return &f;
  return nullptr;
}

std::string formulation_names(bool last_or) {
  const auto& table = formulation_registry();
  std::string s;
  for (size_t k = 0; k < table.size(); ++k)
    s += (k == 0 ? "" : last_or && k + 1 == table.size() ? " or " : ", ") + table[k].name;
  return s;
}

double handover_rtol(const std::string& name) {
  return name == "index3" ? kIndex3HandoverRtol : name == "index1" ? kIndex1HandoverRtol : 0.0;
}

std::string formulation_at(const std::string& name, double rtol) {
  return rtol < handover_rtol(name) ? "index2-ggl" : name;
}

}  // namespace mbdae
