// Canonical JSON: the spec's example, special values, and clear errors for bad input.
#include "rsg/wire/json.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rsg {
namespace {

TEST(Json, SpecExampleRoundTrips) {
  const std::string text =
      R"({"packet_number":5,"group_select":4,"data_select":[0,0,32,0,0,0],"fields":{"q":[0.1,0.2,0.3,0.4,0.5,0.6,0.7]}})";
  const wire::Parsed<wire::StateValues> values_parsed = wire::parse_canonical_json(text);
  ASSERT_TRUE(values_parsed) << values_parsed.error();
  const wire::StateValues& values = *values_parsed;
  EXPECT_EQ(values.doubles(wire::Field::q)[6], 0.7);
  EXPECT_EQ(wire::to_canonical_json(values), text);
}

TEST(Json, SpecialValuesAndScalars) {
  wire::StateValues values;
  values.selection.add(wire::Field::m_ee);
  values.selection.add(wire::Field::q);
  values.selection.add(wire::Field::current_errors);
  values.selection.add(wire::Field::robot_mode);
  values.selection.add(wire::Field::time);
  values.doubles(wire::Field::m_ee)[0] = -0.0;
  auto q = values.doubles(wire::Field::q);
  q[0] = std::nan("");
  q[1] = INFINITY;
  q[2] = -INFINITY;
  q[3] = 8.0;
  values.set_integer(wire::Field::current_errors, 0b101);
  values.set_integer(wire::Field::robot_mode, 2);
  values.set_integer(wire::Field::time, 18446744073709551615ULL);
  const std::string json = wire::to_canonical_json(values);
  EXPECT_NE(json.find(R"("m_ee":-0.0)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("q":["nan","inf","-inf",8,0,0,0])"), std::string::npos) << json;
  EXPECT_NE(
      json.find(
          R"("current_errors":["joint_position_limits_violation","self_collision_avoidance_violation"])"),
      std::string::npos);
  EXPECT_NE(json.find(R"("time":18446744073709551615)"), std::string::npos);

  const wire::Parsed<wire::StateValues> parsed_parsed = wire::parse_canonical_json(json);
  ASSERT_TRUE(parsed_parsed) << parsed_parsed.error();
  const wire::StateValues& parsed = *parsed_parsed;
  EXPECT_TRUE(std::signbit(parsed.doubles(wire::Field::m_ee)[0]));
  EXPECT_TRUE(std::isnan(parsed.doubles(wire::Field::q)[0]));
  EXPECT_EQ(parsed.integer(wire::Field::time), 18446744073709551615ULL);
}

struct BadInput {
  const char* json;
  const char* expected_error;
};

class JsonErrors : public testing::TestWithParam<BadInput> {};

TEST_P(JsonErrors, AreReadable) {
  const wire::Parsed<wire::StateValues> values = wire::parse_canonical_json(GetParam().json);
  EXPECT_FALSE(values);
  EXPECT_NE(values.error().find(GetParam().expected_error), std::string::npos) << values.error();
}

INSTANTIATE_TEST_SUITE_P(
    Json, JsonErrors,
    testing::Values(
        BadInput{"{", "malformed JSON"}, BadInput{"[]", "expected a JSON object"},
        BadInput{R"({"packet_number":16,"group_select":0,"data_select":[0,0,0,0,0,0],"fields":{}})",
                 "packet_number"},
        BadInput{R"({"packet_number":1,"group_select":0,"data_select":[0,0,0,0,0],"fields":{}})",
                 "data_select"},
        BadInput{R"({"packet_number":1,"group_select":4,"data_select":[0,0,32,0,0,0],"fields":{}})",
                 "'q' is selected by data_select but missing"},
        BadInput{R"({"packet_number":1,"group_select":4,"data_select":[0,0,32,0,0,0],"fields":{"q":[1]}})",
                 "q: expected an array of 7 numbers"},
        BadInput{R"({"packet_number":1,"group_select":0,"data_select":[0,0,0,0,0,0],"fields":{"qq":1}})",
                 "'qq' is not a field name"},
        BadInput{
            R"({"packet_number":1,"group_select":0,"data_select":[0,0,0,0,0,0],"fields":{"q":[1,2,3,4,5,6,7]}})",
            "'q' is not selected"},
        BadInput{
            R"({"packet_number":1,"group_select":16,"data_select":[0,0,0,0,128,0],"fields":{"current_errors":["nope"]}})",
            "not an error flag name"},
        BadInput{R"({"packet_number":1,"group_select":0,"data_select":[0,0,0,0,0,0],"fields":{},"extra":1})",
                 "unknown key 'extra'"}));

}  // namespace
}  // namespace rsg
