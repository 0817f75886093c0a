// Sylva's iOS entry point: the whole app (window, Metal surface through wgpu, ARKit session,
// UI) is the Rust static library; winit's iOS backend calls UIApplicationMain itself.
#import "sylva_ios.h"

int main(int argc, char *argv[]) {
    (void)argc;
    (void)argv;
    sylva_ios_main();
    return 0;
}
