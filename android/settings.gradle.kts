// The Android project around the Rust shell crate (this folder's Cargo.toml):
// ./gradlew installDebug builds libsylva_android.so with cargo-ndk and the APK around it.
pluginManagement {
    repositories {
        google()
        mavenCentral()
        gradlePluginPortal()
    }
}
dependencyResolutionManagement {
    repositoriesMode.set(RepositoriesMode.FAIL_ON_PROJECT_REPOS)
    repositories {
        google()
        mavenCentral()
    }
}
rootProject.name = "Sylva"
include(":app")
