// Whether the gateway's DataWriters and DataReaders may share memory with same-host peers
// (--data-sharing; gateway/entities.hpp applies it to every one of them).
#pragma once

namespace rsg::gateway {

enum class DataSharing {
  kAsProfiled,  ///< as the XML profile says (rsg's: AUTOMATIC, same-host readers read shared memory)
  kOff,         ///< never, whatever the profile says (docs/security.md, "Same-host processes")
};

}  // namespace rsg::gateway
