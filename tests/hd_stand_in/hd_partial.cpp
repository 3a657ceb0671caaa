// A libHD that lacks most of HDAPI: hdInitDevice and hdGetError only. For the test that a library named by
// CALLIGRAPHY_LIBHD and refused for its missing symbols is an error, never replaced by another libHD.
extern "C" {

struct HDErrorInfo {
  unsigned int errorCode;
  int internalErrorCode;
  unsigned int hHD;
};

__attribute__((visibility("default"))) unsigned int hdInitDevice(const char*) { return 0; }
__attribute__((visibility("default"))) HDErrorInfo hdGetError() { return HDErrorInfo{0, 0, 0}; }
}
