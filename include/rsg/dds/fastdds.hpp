// The Fast DDS names that differ between Fast DDS 2.x and 3.x and that a user of rsg's DDS API
// needs, so that one program builds against an rsg built on either (docs/fastdds-versions.md):
//
//   rsg::dds::ReturnCode, kOk, kBadParameter   what DataReader::take_next_sample(), ...
//                                              wait_for_acknowledgments() return
//   rsg::dds::succeeded(r)                     DataWriter::write() returns a bool on 2.x, a ReturnCode on 3.x
//   rsg::dds::Duration, kInfinite              timeouts (wait_for_unread_message, ...)
//   rsg::dds::rtps                             the RTPS namespace (GUID_t, Locator_t, ...)
//   RSG_FASTDDS_MAJOR                          2 or 3
//
//   if (rsg::dds::succeeded(writer->write(&sample))) ...
//   while (reader->take_next_sample(&sample, &info) == rsg::dds::kOk) ...
//
// rsg's own code gets these through its internal compat header, which adds what only rsg needs.
#pragma once

#if __has_include(<fastdds/config.hpp>)
#include <fastdds/config.hpp>
#include <fastdds/dds/core/ReturnCode.hpp>
#include <fastdds/dds/core/Time_t.hpp>
/// The major version of the Fast DDS rsg is built against: 2 or 3.
#define RSG_FASTDDS_MAJOR FASTDDS_VERSION_MAJOR
#else
#include <fastdds/rtps/common/Time_t.h>
#include <fastrtps/config.h>
#include <fastrtps/types/TypesBase.h>
#define RSG_FASTDDS_MAJOR FASTRTPS_VERSION_MAJOR
#endif

namespace rsg::dds {

#if RSG_FASTDDS_MAJOR >= 3

namespace rtps = eprosima::fastdds::rtps;
using Duration = eprosima::fastdds::dds::Duration_t;
using ReturnCode = eprosima::fastdds::dds::ReturnCode_t;
inline constexpr ReturnCode kOk = eprosima::fastdds::dds::RETCODE_OK;
inline constexpr ReturnCode kBadParameter = eprosima::fastdds::dds::RETCODE_BAD_PARAMETER;
inline const Duration kInfinite = eprosima::fastdds::dds::c_TimeInfinite;

/// Whether a call that returns a ReturnCode (Fast DDS 3; on 2.x also DataWriter::write's bool)
/// succeeded.
inline bool succeeded(ReturnCode code) { return code == kOk; }

#else  // Fast DDS 2.x

namespace rtps = eprosima::fastrtps::rtps;
using Duration = eprosima::fastrtps::Duration_t;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
inline const ReturnCode kOk = ReturnCode::RETCODE_OK;
inline const ReturnCode kBadParameter = ReturnCode::RETCODE_BAD_PARAMETER;
inline const Duration kInfinite = eprosima::fastrtps::c_TimeInfinite;

inline bool succeeded(ReturnCode code) { return code == kOk; }
inline bool succeeded(bool done) { return done; }

#endif

}  // namespace rsg::dds
