#!/usr/bin/env bash
# The slow validations: every #[ignore]d test that compares the code to a published figure or
# an analytic solution, run one at a time in release, with a table of figure / reference /
# tolerance / pass / wall time. The table and every test's log go to
# reports/validation/<UTC date>-<git describe>/ (commit that directory: it is what makes the
# docs' slow figures reproducible).
#   scripts/validate-all.sh            # all of them (about an hour on 2 quiet cores)
#   scripts/validate-all.sh cavity dkt # only the entries whose id contains one of the words
#   scripts/validate-all.sh --list     # the table without running anything
# Exit status: 0 when every test that ran passed.
#
# One line per validation below: crate | test file (or lib) | test name | figure | reference | tolerance.
# A new ignored validation gets a line here (tests/it/self_contained.rs checks that every ignored
# test of the workspace is listed, or named as an exploration in EXPLORATIONS or a child process
# in CHILDREN).
set -euo pipefail
cd "$(dirname "$0")/.."

VALIDATIONS='
lbdem-lbm|cavity|re1000_matches_ghia|lid-driven cavity Re = 1000, N = 256: u on the vertical centreline|Ghia, Ghia & Shin 1982 Table I|max abs(u - u_Ghia) / U < 0.012 (measured 0.0061)
lbdem-lbm|sangani_acrivos|drag_matches_table_full|drag of a square array of cylinders, L = 128, Φ = 0.05-0.5|Sangani & Acrivos 1982 Table 1|3 % (measured up to 2.6 %)
lbdem-dem|packing|isotropic_compression_packing_fraction_full|jamming packing fraction of 4000 frictionless bidisperse disks, compressed to the target wall stress|O'"'"'Hern et al. 2003: φ_J ≈ 0.84|± 0.02 (measured 0.8416)
lbdem-coupling|sangani_psm|drag_matches_table_full|PSM drag of cylinder arrays at 32 and 64 cells, Φ = 0.1-0.3|Sangani & Acrivos 1982 Table 1|7 % at 32, 2.5 % at 64, error halves
lbdem-coupling|settling_disk|settling_converges_with_resolution|terminal velocity of a disk between walls at 10, 16, 24 cells/d|Faxén 1946 wall-corrected Stokes drag|PSM 6 % and falling to < 1.5 %; bounce-back 1.5 %
lbdem-coupling|darcy|permeability_reference_from_fine_levels|permeability k/L² of a random packing of 14 disks (Φ = 0.30) at L = 64, 128, 256, Richardson-extrapolated|the test'"'"'s FINE_K (second order: ratio 3.87)|1e-6 (the constant it prints)
lbdem-coupling|low_resolution|fine_lattice_reference|permeability k/d̄² of the two-circle packing at 10, 20, 40 cells, Richardson-extrapolated|the test'"'"'s FINE_K (second order)|0.5 %
lbdem-coupling|low_resolution|fine_disk_arrays_meet_the_table|drag of disk arrays at 40 cells/d, Φ = 0.1, 0.3, 0.5|Sangani & Acrivos 1982 Table 1|0.5 %, 3 %, 15 %
lbdem-coupling|surface_grains|a_finer_floating_grain|submerged fraction of a sphere of half the liquid'"'"'s density floating in a free-surface pool, 7.5 nodes of radius|Archimedes: 0.5|± 0.005 (measured 0.4973)
lbdem-coupling|surface_grains|ten_cates_four_cases_at_eight_cells|terminal velocity of a settling sphere, cases E1-E4, 8 cells per diameter|ten Cate et al. 2002 Table 1|4, 2.5, 9, 12 % (measured +2.1, −1.2, −4.7, −7.0 %)
lbdem-coupling|dkt|dkt_phases_at_finer_resolution|drafting, kissing, tumbling of two disks at 12 and 16 cells/d|Glowinski et al. 2001 set-up (phases only)|the three phases occur (test'"'"'s thresholds)
lbdem-coupling|dkt_uhlmann|coarser_lattice_and_the_variants|DKT at 16 cells/d; without the interior-liquid correction, BGK, contact at the surfaces|Uhlmann 2005 Figs. 6a, 7a; Koblitz et al. 2017 Figs. 10a, 10c|0.1 d RMS to the kiss; tumble within the publications'"'"' times
lbdem-coupling|dkt_uhlmann|finer_lattices_converge_into_the_published_envelope|DKT at 32 and 48 cells/d|Uhlmann 2005; Koblitz et al. 2017|as above, and inside the envelope at 48 (allowance: the publications'"'"' own difference)
lbdem|sweep_cli|mass_scaling_by_a_hundred_is_within_the_stated_tolerance_over_sixteen_assemblies|reduced shear cell on 16 random assemblies, mass_scale 100 (Simulation I'"'"'s switch) against 1: ε_vol^DEM, plate force, displacement profile|the unscaled runs, paired (issue 13 item 7)|mean shift + 2 SE: 0.0018, 21 %, 4.6 % of u_y (measured 0.0009, 10.7 %, 2.3 %)
lbdem-coupling|dkt_uhlmann|finest_lattice_stays_in_the_published_envelope|DKT at 64 cells/d|Uhlmann 2005; Koblitz et al. 2017|inside the envelope (allowance: the publications'"'"' own difference)
lbdem-lbm|free_surface|dam_break_front_matches_martin_moyce_fine|2D dam break, column a = 64 nodes, front Z = x/a at the 13 digitised times T ≤ 8.03, no time shift|Martin & Moyce 1952 (REFERENCES.md)|15 % (measured +11.3 % at T = 1.22, −9.3 % at T = 8.03)
lbdem-dem|shear_rheology|flow_curve_against_boyer_et_al|simple shear of 400 lubricated bidisperse spheres (Ness et al. 2017 model, Lees-Edwards), φ = 0.40-0.55: stresses and μ = (−σ_xy + η γ̇)/σ_yy|Boyer, Guazzelli & Pouliquen 2011 μ(I_v), φ(I_v)|stresses rise with φ, μ falls loose → dense by > 2 SE; μ within 20 % at φ ≥ 0.53 (measured −8.6 %, +1.4 %)
lbdem|lib|reduced_extruder_reaches_the_mass_balance|reduced Ness et al. 2017 extruder (barrel 16 d, die 8 d, case A paste) run to its mass balance|Ness et al. 2017 steady-state check: inserted and removed rates equal|imbalance <= 0.15 over a 30 t window with >= 100 grains out; die velocity > 0
'
# Ignored tests that are explorations (they print, they assert nothing): not validations.
# shellcheck disable=SC2034
EXPLORATIONS='
lbdem-lbm|stability|explore_tau|
lbdem-dem|shear_rheology|ci_case_against_smaller_step_and_stokes_number|
lbdem-dem|extruder|explore_reduced_flow|
'
# Ignored tests that another test runs as a child process (the fuzz watchdog ends the process it
# runs in): neither validations nor explorations, not run by this script.
# shellcheck disable=SC2034
CHILDREN='
lbdem|fuzz|hang_probe|run by a_hanging_execution_fails_the_harness_and_leaves_its_input
'

list_only=0
filters=()
for a in "$@"; do
  case "$a" in
    --list) list_only=1 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "validate-all.sh: unknown option $a (options: --list, --help; other arguments filter by name)" >&2; exit 2 ;;
    *) filters+=("$a") ;;
  esac
done

selected() {
  [ ${#filters[@]} -eq 0 ] && return 0
  for f in "${filters[@]}"; do
    case "$1" in *"$f"*) return 0 ;; esac
  done
  return 1
}

version=$(git describe --always --dirty 2>/dev/null || echo unknown)
commit=$(git rev-parse HEAD 2>/dev/null || echo unknown)
stamp=$(date -u +%Y-%m-%d)
dir="reports/validation/$stamp-$version"
table="| id | figure | reference | tolerance | pass | wall (s) |\n|---|---|---|---|---|---|\n"
failed=0
ran=0

if [ $list_only -eq 0 ]; then
  mkdir -p "$dir/logs"
  cargo build --release --tests --workspace --quiet
fi

while IFS='|' read -r crate file name figure reference tolerance; do
  [ -z "$crate" ] && continue
  id="$crate/$file/$name"
  selected "$id" || continue
  if [ $list_only -eq 1 ]; then
    table+="| $id | $figure | $reference | $tolerance | - | - |\n"
    continue
  fi
  log="$dir/logs/$crate-$file-$name.log"
  echo "== $id ($(date -u +%H:%M:%S), load $(cut -d' ' -f1 /proc/loadavg))" >&2
  t0=$(date +%s.%N)
  # file "lib": a test of the crate's library (src/**/tests), found by its name.
  # The engine crates have one test binary each (tests/main.rs, named after the crate), whose
  # tests are <file>::<name>; so has the lbdem crate (tests/it/main.rs, binary `it`), but for
  # its fuzz harness (tests/fuzz.rs, binary `fuzz`), which installs its own global allocator.
  case "$crate" in
    lbdem-lbm | lbdem-coupling | lbdem-dem) suite=${crate#lbdem-}; full="$file::$name" ;;
    lbdem) if [ "$file" = fuzz ]; then suite=fuzz; full=$name; else suite=it; full="$file::$name"; fi ;;
    *) suite=$file; full=$name ;;
  esac
  if [ "$file" = lib ]; then target=(--lib); exact=(); else target=(--test "$suite"); exact=(--exact); fi
  if cargo test --release --quiet -p "$crate" "${target[@]}" -- --ignored "${exact[@]}" "$full" --nocapture >"$log" 2>&1; then
    pass=yes
  else
    pass=NO
    failed=$((failed + 1))
  fi
  ran=$((ran + 1))
  wall=$(echo "$(date +%s.%N) - $t0" | bc)
  # A filter that names no test would pass vacuously: cargo reports "running 0 tests".
  if ! grep -q "test result: .* 1 passed\|test result: FAILED" "$log"; then
    pass="NOT RUN"
    failed=$((failed + 1))
  fi
  table+="| $id | $figure | $reference | $tolerance | $pass | $(printf %.0f "$wall") |\n"
done <<<"$VALIDATIONS"

if [ $list_only -eq 1 ]; then
  printf "%b" "$table"
  exit 0
fi

{
  echo "# Validation run $stamp"
  echo
  echo "- code version: $version ($commit, at the start of the run)"
  echo "- command: scripts/validate-all.sh ${filters[*]:-}"
  echo "- machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load at the end $(cut -d' ' -f1 /proc/loadavg)"
  echo "- $ran run, $failed failed or not run; each test's output in logs/"
  echo
  printf "%b" "$table"
} >"$dir/README.md"
cat "$dir/README.md"
[ $failed -eq 0 ]
