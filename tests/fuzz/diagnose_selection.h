// The fuzz entry that drives diagnose's whole selection, not only its parsers (tests/fuzz/README.md,
// harness fuzz_diagnose_selection). The input bytes are read as a stream of choices that build a
// small random case end to end:
//   - a spectra model file (lights as Gaussians, point tables or shipped LED files; an analytic,
//     measured or no long-pass; leak measured, computed or none; random baseline fluorophores,
//     candidates, extra fluorophores, fit range, grid, selection settings, sometimes shared
//     concentrations, plausible ranges or a small layered_tissue block), written as JSON and read
//     by the model parser;
//   - a data folder (index.csv and one CSV per spectrum: 1-3 subjects, 1-2 sites, the model's
//     lights, 1-2 locations, a random sampling), its values made by diagnose's own forward model
//     under a random hidden state (0-2 causes with random parameters, random amplitudes), with
//     noise and sometimes damage (a zero, negative, constant or huge spectrum);
//   - a job (groups, report_by, --where, --z, --max-causes, --fit-on/--predict, output files);
// then runs `run_diagnose_job` on it; or (one case in five) a synthetic camera patch set, thinned
// and damaged, through the camera problem's selection and report. An InputError is the expected
// answer to a case the tools refuse; any other exception, a crash or a sanitizer report is a finding.
// Sizes are kept small (at most 24 spectra, a grid of 1 nm or coarser, at most 3 causes) so that a
// case takes a fraction of a second.
#pragma once
#include <cstddef>
#include <cstdint>

namespace ofl::fuzz {

void run_diagnose_selection(const uint8_t* data, size_t size);

}  // namespace ofl::fuzz
