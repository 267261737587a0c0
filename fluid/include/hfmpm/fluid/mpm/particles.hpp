// Fluid material points on the crack manifold, structure of arrays. Units SI,
// per unit thickness. Particles are kept sorted by arc length and contiguous:
// particle p occupies [s_p - l_p/2, s_p + l_p/2], the end of one is the start
// of the next, and particle 0 starts at the mouth (it is the inlet particle).
//
// Deformation gradient with two components (docs/fluid.md):
//   F11 stretch along the crack, F11 = l / l0 (l0 the length on entry);
//   F22 = w / w0, w the crack width averaged over the particle's domain and w0
//       the width on entry.
// J = F11 F22 = V / V0 with V = l w the volume (m^2 per unit thickness) and
// V0 = m / rho0 the volume at zero pressure. Every particle keeps the
// invariant m = rho0 (l / F11) w0.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace hfmpm::fluid::mpm {

struct FluidParticles {
  std::vector<double> s;         // m, arc length of the centre from the mouth
  std::vector<double> length;    // m, l, extent along the crack
  std::vector<double> width;     // m, w, mean crack width over [s - l/2, s + l/2]
  std::vector<double> mass;      // kg/m, per unit thickness
  std::vector<double> velocity;  // m/s, mean over the cross-section, along +s
  // 1/s, dv/ds: the affine part of the particle's velocity field (APIC;
  // FluidConfig::affine), v(s) = velocity + gradient (s - s_p) over its domain.
  std::vector<double> gradient;
  std::vector<double> f11;       // -, stretch along the crack
  std::vector<double> f22;       // -, w / w0
  std::vector<double> w0;        // m, width on entry (> 0: floored at the solver's min_width)
  std::vector<double> pressure;  // Pa, >= 0 (no tension)

  std::size_t size() const { return s.size(); }
  // Contiguous: particle p + 1 starts where p ends. The solver moves that
  // shared end once, as p's end, and starts p + 1 there: moved as two ends,
  // the round-off between s + l/2 and the next s - l/2 (1e-10 m) grew by the
  // stretching at a front by a factor of 1000 in 200 steps and then ran away,
  // leaving two particles on top of each other moving at 100-300 m/s without
  // going anywhere, and the advective step 180 times shorter (the robustness
  // matrix's field-km100, docs/verification.md).
  double start(std::size_t p) const { return s[p] - 0.5 * length[p]; }  // m, rear end
  double end(std::size_t p) const { return s[p] + 0.5 * length[p]; }    // m, front end
  double volume(std::size_t p) const { return length[p] * width[p]; }   // m^2
  double jacobian(std::size_t p) const { return f11[p] * f22[p]; }      // -, J = V / V0

  // Insert a particle before index `at` (at == size() appends). The state
  // fields (w, F11, F22, w0, p) are set by the solver.
  void insert(std::size_t at, double centre, double l, double m, double v) {
    for (auto* field : fields()) field->push_back(0.0);
    s.back() = centre;
    length.back() = l;
    mass.back() = m;
    velocity.back() = v;
    f11.back() = f22.back() = 1.0;
    // Rotate the new entry into place (vector::insert trips GCC 12's
    // -Wnull-dereference false positive at -O3).
    for (auto* field : fields())
      std::rotate(field->begin() + static_cast<std::ptrdiff_t>(at), field->end() - 1, field->end());
  }
  void erase(std::size_t at) {
    for (auto* field : fields()) field->erase(field->begin() + static_cast<std::ptrdiff_t>(at));
  }

 private:
  std::array<std::vector<double>*, 10> fields() {
    return {&s, &length, &width, &mass, &velocity, &gradient, &f11, &f22, &w0, &pressure};
  }
};

}  // namespace hfmpm::fluid::mpm
