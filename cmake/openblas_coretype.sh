# Sourced by run.sh and benchmarks/against_commit.sh: when OpenBLAS does not know this CPU and would
# run its kernels without AVX2 on a CPU that has AVX2 and FMA, exports OPENBLAS_CORETYPE naming the
# kernels for what the CPU has (SkylakeX with AVX-512, else Haswell) and says so on stderr. OpenBLAS
# chooses its kernels by CPU model when it loads; Debian 12's 0.3.21 takes Intel's Emerald Rapids
# (model 207) for a Prescott (SSE3), and SEIF's thesis-scale run then takes 1.94 s instead of 1.35
# (docs/benchmarks.md, "OpenBLAS's kernels on a CPU it does not know"). A value set by the caller is kept.
openblas_kernels_for_cpu() {  # prints the OPENBLAS_CORETYPE this CPU wants, or nothing without AVX2 + FMA
  local flags
  flags=" $(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null | cut -d: -f2 || true) "  # none on other architectures
  local f
  for f in avx2 fma; do [[ $flags == *" $f "* ]] || return 0; done
  for f in avx512f avx512cd avx512bw avx512dq avx512vl; do [[ $flags == *" $f "* ]] || { echo Haswell; return 0; }; done
  echo SkylakeX
}
openblas_core_in_use() {  # the kernels OpenBLAS chose when loaded, or nothing when it cannot be loaded
  python3 -c 'import ctypes
try:
    lib = ctypes.CDLL("libopenblas.so.0")
except OSError:
    raise SystemExit
lib.openblas_get_corename.restype = ctypes.c_char_p
print(lib.openblas_get_corename().decode())' 2>/dev/null || true
}
if [ -z "${OPENBLAS_CORETYPE:-}" ]; then
  sextant_wanted_kernels=$(openblas_kernels_for_cpu)
  if [ -n "$sextant_wanted_kernels" ]; then
    sextant_chosen_kernels=$(openblas_core_in_use)
    case "${sextant_chosen_kernels,,}" in
      ""|haswell|zen|excavator|skylakex|cooperlake|sapphirerapids) ;;  # not loadable, or AVX2 kernels already
      *)
        export OPENBLAS_CORETYPE=$sextant_wanted_kernels
        echo "sextant: OpenBLAS takes this CPU for a $sextant_chosen_kernels; its $sextant_wanted_kernels kernels" \
          "run instead (OPENBLAS_CORETYPE=$sextant_wanted_kernels; set it yourself to choose others)" >&2 ;;
    esac
  fi
  unset sextant_wanted_kernels sextant_chosen_kernels
fi
