#pragma once
// PVB_ADDRESS_SANITIZER is 1 in a build with AddressSanitizer, whichever the
// compiler: GCC defines __SANITIZE_ADDRESS__, clang answers __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define PVB_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PVB_ADDRESS_SANITIZER 1
#endif
#endif
#ifndef PVB_ADDRESS_SANITIZER
#define PVB_ADDRESS_SANITIZER 0
#endif
