// The C interface of the Rust static library libsylva_ios.a (ios/src/lib.rs).
#ifndef SYLVA_IOS_H
#define SYLVA_IOS_H

/// Runs the app: winit's iOS event loop takes over the main thread (UIApplicationMain inside);
/// never returns.
void sylva_ios_main(void);

#endif
