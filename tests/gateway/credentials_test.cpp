// ${CREDENTIALS_DIRECTORY} in a participant profile's properties (src/gateway/credentials.hpp):
// the key systemd's LoadCredential= hands a DynamicUser service.
#include "gateway/credentials.hpp"

#include <gtest/gtest.h>

#include "rsg/error.hpp"

namespace rsg::gateway {
namespace {

TEST(Credentials, TheVariableBecomesTheDirectorySystemdGave) {
  EXPECT_EQ(expand_credentials_directory("file://${CREDENTIALS_DIRECTORY}/gateway.key",
                                         "/run/credentials/rsg-gateway@robot1.service", "p"),
            "file:///run/credentials/rsg-gateway@robot1.service/gateway.key");
  EXPECT_EQ(expand_credentials_directory("${CREDENTIALS_DIRECTORY}:${CREDENTIALS_DIRECTORY}", "/c", "p"),
            "/c:/c");
}

TEST(Credentials, AValueWithoutTheVariableIsLeftAsItIsEvenWithoutADirectory) {
  EXPECT_EQ(expand_credentials_directory("file:///etc/rsg/pki/ca.pem", nullptr, "p"),
            "file:///etc/rsg/pki/ca.pem");
  EXPECT_EQ(expand_credentials_directory("$CREDENTIALS_DIRECTORY", nullptr, "p"), "$CREDENTIALS_DIRECTORY");
}

TEST(Credentials, TheVariableWithoutADirectoryIsAnInputErrorNamingTheProperty) {
  for (const char* directory : {static_cast<const char*>(nullptr), ""}) {
    try {
      expand_credentials_directory("file://${CREDENTIALS_DIRECTORY}/gateway.key", directory,
                                   "participant profile 'rsg_secure_gateway', property "
                                   "dds.sec.auth.builtin.PKI-DH.private_key");
      FAIL() << "no error";
    } catch (const InputError& error) {
      EXPECT_STREQ(
          error.what(),
          "participant profile 'rsg_secure_gateway', property dds.sec.auth.builtin.PKI-DH.private_key: "
          "names ${CREDENTIALS_DIRECTORY}, but CREDENTIALS_DIRECTORY is not set (the unit needs "
          "LoadCredential=, docs/security.md)");
    }
  }
}

}  // namespace
}  // namespace rsg::gateway
