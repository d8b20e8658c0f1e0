#include "caliper/rtc/transport_security.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace caliper::rtc {
namespace {

// a PKI made by `launch/caliper certs` in a temporary directory: a CA, host h1, user u1, and a
// second CA with host h2
class TransportSecurityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    char pattern[] = "/tmp/caliper-tls-XXXXXX";
    dir_ = mkdtemp(pattern);
    const char* src = std::getenv("CALIPER_SOURCE_DIR");
    ASSERT_NE(src, nullptr) << "ctest sets CALIPER_SOURCE_DIR";
    const std::string certs = "bash " + std::string(src) + "/launch/caliper certs ";
    for (const std::string& args :
         {"ca --dir " + dir_ + "/pki", "host h1 --dir " + dir_ + "/pki",
          "user u1 --dir " + dir_ + "/pki", "ca --dir " + dir_ + "/other",
          "host h2 --dir " + dir_ + "/other"})
      ASSERT_EQ(std::system((certs + args + " 2>/dev/null").c_str()), 0) << args;
  }
  static void TearDownTestSuite() {
    ASSERT_EQ(std::system(("rm -rf " + dir_).c_str()), 0);
  }
  void SetUp() override {
    const char* user = std::getenv("USER");
    user_ = user != nullptr ? user : "";
    unsetenv("CALIPER_PKI");
    unsetenv("CALIPER_TLS_IDENTITY");
    unsetenv("CALIPER_INSECURE");
  }
  void TearDown() override { setenv("USER", user_.c_str(), 1); }
  static SecurityRequest Network(const std::string& identity = "hosts/h1") {
    SecurityRequest r;
    r.endpoint = "giop:tcp:198.51.100.1:";
    r.naming_address = "corbaname::198.51.100.1:2809";
    r.pki_dir = dir_ + "/pki";
    r.identity = identity;
    r.component = true;
    return r;
  }
  static std::string ErrorOf(const SecurityRequest& r) {
    try {
      ResolveSecurity(r);
    } catch (const SecurityError& e) {
      return e.what();
    }
    return "";
  }
  static std::string dir_;
  std::string user_;
};
std::string TransportSecurityTest::dir_;

TEST_F(TransportSecurityTest, LoopbackNeedsNothing) {
  SecurityRequest r;
  r.endpoint = "giop:tcp:127.0.0.1:";
  r.naming_address = "corbaname::127.0.0.1:2809";
  r.pki_dir = dir_ + "/nowhere";
  const TransportSecurity s = ResolveSecurity(r);
  EXPECT_EQ(s.transport, Transport::kLoopback);
  EXPECT_EQ(s.endpoint, "giop:tcp:127.0.0.1:");
  EXPECT_FALSE(s.network_endpoint);
}

TEST_F(TransportSecurityTest, NetworkModeIsTlsOnAnSslEndpoint) {
  const TransportSecurity s = ResolveSecurity(Network());
  EXPECT_EQ(s.transport, Transport::kTls);
  EXPECT_EQ(s.endpoint, "giop:ssl:198.51.100.1:");
  EXPECT_TRUE(s.network_endpoint);
  EXPECT_EQ(s.key_file, dir_ + "/pki/hosts/h1.pem");
  EXPECT_EQ(s.key_password.size(), 64u);  // the random password of certs, without its newline
}

TEST_F(TransportSecurityTest, RemoteNamingServiceAloneMeansTls) {
  SecurityRequest r = Network("users/u1");
  r.endpoint = "giop:tcp:127.0.0.1:";
  const TransportSecurity s = ResolveSecurity(r);
  EXPECT_EQ(s.transport, Transport::kTls);
  EXPECT_EQ(s.endpoint, "giop:tcp:127.0.0.1:");  // listens on loopback still
  EXPECT_FALSE(s.network_endpoint);
}

TEST_F(TransportSecurityTest, AHostNameStartingWith127IsANetworkAddress) {
  SecurityRequest r = Network();
  r.endpoint = "giop:tcp:127.foo.example.com:";
  r.naming_address = "corbaname::127.0.0.1:2809";
  const TransportSecurity s = ResolveSecurity(r);
  EXPECT_EQ(s.transport, Transport::kTls);
  EXPECT_EQ(s.endpoint, "giop:ssl:127.foo.example.com:");
  EXPECT_TRUE(s.network_endpoint);
  r.pki_dir = dir_ + "/nowhere";  // and without certificates: refused, not plain GIOP
  EXPECT_NE(ErrorOf(r).find("listening on giop:tcp:127.foo.example.com:"), std::string::npos)
      << ErrorOf(r);
}

TEST_F(TransportSecurityTest, LocalhostIsLoopback) {
  SecurityRequest r;
  r.endpoint = "giop:tcp:localhost:";
  r.naming_address = "corbaname::localhost:2809";
  r.pki_dir = dir_ + "/nowhere";
  EXPECT_EQ(ResolveSecurity(r).transport, Transport::kLoopback);
}

TEST_F(TransportSecurityTest, APassedNetworkEndpointMeansNetworkMode) {
  SecurityRequest r;
  r.endpoint = "giop:tcp:127.0.0.1:";
  r.naming_address = "corbaname::127.0.0.1:2809";
  r.pki_dir = dir_ + "/nowhere";
  r.extra_endpoints = {"giop:unix:", "giop:tcp:127.0.0.1:5000"};
  EXPECT_EQ(ResolveSecurity(r).transport, Transport::kLoopback);
  r.extra_endpoints.push_back("giop:tcp::");  // every interface
  const std::string error = ErrorOf(r);
  EXPECT_NE(error.find("listening on giop:tcp:: (-ORBendPoint)"), std::string::npos) << error;
  r.pki_dir = dir_ + "/pki";
  r.identity = "hosts/h1";
  EXPECT_EQ(ResolveSecurity(r).transport, Transport::kTls);
  r.insecure = true;
  EXPECT_EQ(ResolveSecurity(r).transport, Transport::kInsecure);
  r.extra_endpoints = {"giop:ssl:127.0.0.1:"};
  EXPECT_NE(ErrorOf(r).find("with the TLS endpoint giop:ssl:127.0.0.1:"), std::string::npos);
}

TEST_F(TransportSecurityTest, TlsRefusesPlainGiopOnEveryEndpoint) {
  // listening on loopback (a remote naming service) or on the network, with or without plain
  // endpoints passed through: the server rule is there in every case
  for (const std::string endpoint : {"giop:tcp:198.51.100.1:", "giop:tcp:127.0.0.1:"}) {
    SecurityRequest r = Network();
    r.endpoint = endpoint;
    r.extra_endpoints = {"giop:tcp::"};
    const TransportSecurity s = ResolveSecurity(r);
    ASSERT_EQ(s.transport, Transport::kTls) << endpoint;
    const std::vector<std::string> options = SecurityOrbOptions(s);
    const std::vector<std::string> expected = {"-ORBclientTransportRule", "* ssl",
                                               "-ORBserverTransportRule", "* ssl"};
    EXPECT_EQ(options, expected) << endpoint;
  }
  // SecurityOrbOptions made TLS this process's transport: back to loopback for the other tests
  InstallProcessSecurity(TransportSecurity{});
  EXPECT_EQ(ProcessSecurity().transport, Transport::kLoopback);
}

TEST_F(TransportSecurityTest, InsecureStaysPlain) {
  SecurityRequest r = Network();
  r.insecure = true;
  const TransportSecurity s = ResolveSecurity(r);
  EXPECT_EQ(s.transport, Transport::kInsecure);
  EXPECT_EQ(s.endpoint, "giop:tcp:198.51.100.1:");
}

TEST_F(TransportSecurityTest, RejectsInsecureWithTlsAddresses) {
  SecurityRequest r = Network();
  r.insecure = true;
  r.endpoint = "giop:ssl:198.51.100.1:";
  EXPECT_NE(ErrorOf(r).find("--insecure"), std::string::npos);
  r.endpoint = "giop:tcp:198.51.100.1:";
  r.naming_address = "corbaname:ssliop:198.51.100.1:2809";
  EXPECT_NE(ErrorOf(r).find("TLS naming service"), std::string::npos);
}

TEST_F(TransportSecurityTest, MissingCaSaysHowToMakeOne) {
  SecurityRequest r = Network();
  r.pki_dir = dir_ + "/nowhere";
  const std::string error = ErrorOf(r);
  EXPECT_NE(error.find("no CA certificate " + dir_ + "/nowhere/ca.pem"), std::string::npos) << error;
  EXPECT_NE(error.find("launch/caliper certs ca --dir " + dir_ + "/nowhere"), std::string::npos)
      << error;
}

TEST_F(TransportSecurityTest, MissingIdentityNamesWhereItLooked) {
  setenv("CALIPER_HOST", "nohost", 1);
  setenv("USER", "nobody-here", 1);
  const std::string error = ErrorOf(Network(""));
  unsetenv("CALIPER_HOST");
  EXPECT_NE(error.find(dir_ + "/pki/hosts/nohost.pem"), std::string::npos) << error;
  EXPECT_NE(error.find(dir_ + "/pki/users/nobody-here.pem"), std::string::npos) << error;
  EXPECT_NE(error.find("launch/caliper certs host NAME"), std::string::npos) << error;
}

TEST_F(TransportSecurityTest, DefaultIdentityIsTheHostThenTheUser) {
  setenv("CALIPER_HOST", "h1", 1);
  setenv("USER", "u1", 1);
  SecurityRequest r = Network("");
  EXPECT_EQ(ResolveSecurity(r).identity, "hosts/h1");
  r.component = false;
  EXPECT_EQ(ResolveSecurity(r).identity, "users/u1");
  setenv("USER", "nobody-here", 1);  // a client without a user identity falls back to the host's
  EXPECT_EQ(ResolveSecurity(r).identity, "hosts/h1");
  unsetenv("CALIPER_HOST");
}

TEST_F(TransportSecurityTest, RejectsAWrongKeyPassword) {
  const std::string pem = dir_ + "/pki/hosts/h1.pem", copy = dir_ + "/wrong.pem";
  ASSERT_EQ(std::system(("cp -p " + pem + " " + copy).c_str()), 0);
  std::ofstream(dir_ + "/wrong.pass") << "not-the-password\n";
  const std::string error = ErrorOf(Network(copy));
  EXPECT_NE(error.find("does not load with the password"), std::string::npos) << error;
}

TEST_F(TransportSecurityTest, RejectsAnEmptyKeyPassword) {
  ASSERT_EQ(std::system(("cp -p " + dir_ + "/pki/hosts/h1.pem " + dir_ + "/empty.pem").c_str()), 0);
  std::ofstream(dir_ + "/empty.pass") << "\n";
  EXPECT_NE(ErrorOf(Network(dir_ + "/empty.pem")).find("is empty"), std::string::npos);
}

TEST_F(TransportSecurityTest, RejectsAnIdentityOfAnotherCa) {
  const std::string error = ErrorOf(Network(dir_ + "/other/hosts/h2.pem"));
  EXPECT_NE(error.find("does not verify against " + dir_ + "/pki/ca.pem"), std::string::npos)
      << error;
}

TEST_F(TransportSecurityTest, CertsWritesPrivateFiles) {
  for (const std::string f : {"/pki/hosts/h1.pem", "/pki/hosts/h1.pass", "/pki/private/ca.key",
                              "/pki/private/ca.pass"}) {
    struct stat st {};
    ASSERT_EQ(stat((dir_ + f).c_str(), &st), 0) << f;
    EXPECT_EQ(st.st_mode & 0777, 0600u) << f;
  }
}

TEST(AddressTest, HostOfNamingAddresses) {
  EXPECT_EQ(AddressHost("corbaname::10.0.0.1:2809"), "10.0.0.1");
  EXPECT_EQ(AddressHost("corbaname:ssliop:head:4000#a/b"), "head");
  EXPECT_EQ(AddressHost("corbaloc:iiop:1.2@10.0.0.2:2809/NameService"), "10.0.0.2");
  EXPECT_EQ(AddressHost("corbaname::[::1]:2809"), "::1");
  EXPECT_EQ(AddressHost("IOR:0102"), "");
}

TEST(AddressTest, LoopbackIsAnAddressNotAPrefix) {
  EXPECT_TRUE(IsLoopbackHost("127.0.0.1"));
  EXPECT_TRUE(IsLoopbackHost("127.1.2.3"));
  EXPECT_TRUE(IsLoopbackHost("::1"));
  EXPECT_TRUE(IsLoopbackHost("0:0:0:0:0:0:0:1"));
  EXPECT_TRUE(IsLoopbackHost("::ffff:127.0.0.1"));
  EXPECT_TRUE(IsLoopbackHost("localhost"));
  EXPECT_TRUE(IsLoopbackHost("LocalHost"));
  EXPECT_FALSE(IsLoopbackHost("10.0.0.1"));
  EXPECT_FALSE(IsLoopbackHost("128.0.0.1"));
  EXPECT_FALSE(IsLoopbackHost("::2"));
  EXPECT_FALSE(IsLoopbackHost("::ffff:10.0.0.1"));
  EXPECT_FALSE(IsLoopbackHost(""));  // every interface
  // host names other than localhost may point anywhere: network addresses
  EXPECT_FALSE(IsLoopbackHost("127.foo.example.com"));
  EXPECT_FALSE(IsLoopbackHost("127.0.0.1.example.com"));
  EXPECT_FALSE(IsLoopbackHost("localhost.example.com"));
  EXPECT_FALSE(IsLoopbackHost("127.1"));  // not a dotted quad: a name to resolve
}

TEST(AddressTest, PlainNamingAddressUnchangedWithoutTls) {
  EXPECT_EQ(SecureNamingAddress("corbaname::10.0.0.1:2809"), "corbaname::10.0.0.1:2809");
}

}  // namespace
}  // namespace caliper::rtc
