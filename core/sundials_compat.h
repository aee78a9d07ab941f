// The differences between SUNDIALS 6 (Debian's 6.4) and 7 that mbdae meets, chosen by
// SUNDIALS_VERSION_MAJOR from sundials/sundials_config.h. `sunrealtype` exists in both (7 removed
// `realtype`): the code uses it directly. How the 7 branch was checked: docs/sundials.md.
#pragma once

#include <idas/idas.h>
#include <sundials/sundials_config.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>

#include <cstdlib>
#include <string>

namespace mbdae {

// Return codes of a custom SUNLinearSolver (7 removed SUNLS_SUCCESS and the unrecoverable
// SUNLS_* failures in favour of the SUNErrCode values).
#if SUNDIALS_VERSION_MAJOR >= 7
constexpr int kLinSolSuccess = SUN_SUCCESS;
constexpr int kLinSolFailUnrecoverable = SUN_ERR_EXT_FAIL;
#else
constexpr int kLinSolSuccess = SUNLS_SUCCESS;
constexpr int kLinSolFailUnrecoverable = SUNLS_PACKAGE_FAIL_UNREC;
#endif

// A serial SUNContext (the communicator argument is a void* in 6, a SUNComm in 7). Null on failure.
inline SUNContext make_sun_context() {
  SUNContext ctx = nullptr;
#if SUNDIALS_VERSION_MAJOR >= 7
  if (SUNContext_Create(SUN_COMM_NULL, &ctx) != 0) return nullptr;
#else
  if (SUNContext_Create(nullptr, &ctx) != 0) return nullptr;
#endif
  return ctx;
}

namespace detail {
inline void keep_error(int code, const char* function, const char* msg, std::string* last) {
  if (code >= 0) return;  // warnings
  *last = std::string(function ? function : "") + ": " + (msg ? msg : "");
}
#if SUNDIALS_VERSION_MAJOR >= 7
inline void sun_error_handler(int, const char* function, const char*, const char* msg, SUNErrCode code,
                              void* data, SUNContext) {
  keep_error(code, function, msg, static_cast<std::string*>(data));
}
#else
inline void ida_error_handler(int code, const char*, const char* function, char* msg, void* data) {
  keep_error(code, function, msg, static_cast<std::string*>(data));
}
#endif
}  // namespace detail

// IDA's error messages ("function: message") go to *last_error instead of stderr, where IDA
// prints them by default (also under `mbdae run --quiet`). 6: IDA's own handler; 7: the
// context's handler stack, cleared first (its default handler logs to stderr). Returns a
// negative flag on failure.
inline int keep_ida_errors(void* ida_mem, SUNContext ctx, std::string* last_error) {
#if SUNDIALS_VERSION_MAJOR >= 7
  (void)ida_mem;
  if (const int flag = SUNContext_ClearErrHandlers(ctx)) return flag < 0 ? flag : -flag;
  const int flag = SUNContext_PushErrHandler(ctx, detail::sun_error_handler, last_error);
  return flag < 0 ? flag : -flag;
#else
  (void)ctx;
  return IDASetErrHandlerFn(ida_mem, detail::ida_error_handler, last_error);
#endif
}

// IDA's name of a return flag. IDAGetReturnFlagName returns a malloc'd string (in 6 and 7):
// copied and freed here.
inline std::string ida_flag_name(int flag) {
  char* name = IDAGetReturnFlagName(flag);
  if (!name) return "IDA flag " + std::to_string(flag);
  std::string s(name);
  std::free(name);
  return s;
}

}  // namespace mbdae
