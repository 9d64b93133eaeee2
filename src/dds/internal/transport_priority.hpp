// INTERNAL, not part of rsg's API and not installed (src/dds/internal/).
//
// RSG_FASTDDS_TRANSPORT_PRIORITY: 1 where Fast DDS passes a writer's transport priority down to the
// transports, as 3.4 and later do (eProsima/Fast-DDS#5933): ChainingTransport gained
// send_w_priority() and SenderResource a send() with the priority, the one without it deprecated
// (an error under -Werror). A ChainingTransport of rsg's (the guard, src/dds/rtps_guard.cpp; the
// tests' recorder, tests/dds/sent_data_recorder.hpp) calls the one the Fast DDS it is built on
// has. 3.1.2 and 3.6.1 are the 3.x rsg was built on; 3.2 and 3.3 are taken for the old interface
// (not built here). Apart from fastdds_compat.hpp so that these two files need nothing else of it.
#pragma once

#include "rsg/dds/fastdds.hpp"

#if RSG_FASTDDS_MAJOR >= 3 && (FASTDDS_VERSION_MAJOR > 3 || FASTDDS_VERSION_MINOR >= 4)
#define RSG_FASTDDS_TRANSPORT_PRIORITY 1
#else
#define RSG_FASTDDS_TRANSPORT_PRIORITY 0
#endif
