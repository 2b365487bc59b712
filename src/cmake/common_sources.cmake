# common sources (lib/common/): action codes, the road's vocabulary (route kinds, road parts), the one atomic file write, the random number
# generator, the road snapshot every other folder reads, and the HMAC tags that authenticate
# advisories and model submissions, and what the core was built for. Includes nothing else of
# the core.
list(APPEND PALCAS_CORE_SOURCES
  lib/common/action.cpp
  lib/common/rng.cpp
  lib/common/road_snapshot.cpp
  lib/common/message_auth.cpp
  lib/common/atomic_file.cpp
  lib/common/road_terms.cpp
  lib/common/build_info.cpp
)
