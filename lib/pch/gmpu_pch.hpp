// The headers most of the library's sources include, precompiled once for all of them
// (meson's cpp_pch in lib/meson.build): Eigen's are the bulk of each source's parse. The
// library is compiled several times over in `make test` (release, sanitizers,
// fuzzing, the Python wheels, a meson subproject). Every source still includes what it uses:
// `make test-tsan` builds the library with -Db_pch=false, which fails on a source that
// leans on this header.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <nanoflann.hpp>
