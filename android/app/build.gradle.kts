// Sylva's APK: a NativeActivity (MainActivity) loading libsylva_android.so, built from the Rust
// crate in android/ by cargo-ndk for arm64-v8a. ARCore is optional: the AAR ships
// libarcore_sdk_c.so, which the Rust library links against.
import java.io.File

plugins {
    id("com.android.application")
    id("org.jetbrains.kotlin.android")
}

android {
    namespace = "org.sylva.app"
    compileSdk = 35
    ndkVersion = "27.2.12479018"

    defaultConfig {
        applicationId = "org.sylva.app"
        minSdk = 24
        targetSdk = 35
        versionCode = 1
        versionName = "0.1.0"
        ndk { abiFilters += listOf("arm64-v8a") }
    }

    buildTypes {
        release {
            isMinifyEnabled = false
        }
    }
    compileOptions {
        sourceCompatibility = JavaVersion.VERSION_17
        targetCompatibility = JavaVersion.VERSION_17
    }
    kotlinOptions { jvmTarget = "17" }
    sourceSets["main"].jniLibs.srcDir(layout.buildDirectory.dir("rustJniLibs"))
    packaging { jniLibs { useLegacyPackaging = true } }
}

// ARCore's native library, unpacked from its AAR so the Rust linker finds libarcore_sdk_c.so.
val arcore: Configuration by configurations.creating

dependencies {
    implementation("com.google.ar:core:1.47.0")
    arcore("com.google.ar:core:1.47.0@aar")
    implementation("androidx.core:core-ktx:1.15.0")
}

val arcoreNativeDir = layout.buildDirectory.dir("arcore-native")

val extractArcoreNative by tasks.registering(Copy::class) {
    from({ arcore.map { zipTree(it) } }) {
        include("jni/arm64-v8a/libarcore_sdk_c.so")
        eachFile { path = name }
        includeEmptyDirs = false
    }
    into(arcoreNativeDir)
}

// cargo ndk -t arm64-v8a -P 24 -o build/rustJniLibs build --release -p sylva-android
val cargoNdk by tasks.registering(Exec::class) {
    dependsOn(extractArcoreNative)
    workingDir = rootDir.parentFile
    val out = layout.buildDirectory.dir("rustJniLibs").get().asFile
    val linkDir = arcoreNativeDir.get().asFile
    environment("RUSTFLAGS", "-L native=" + linkDir.absolutePath)
    commandLine(
        "cargo", "ndk", "-t", "arm64-v8a", "-P", "24", "-o", out.absolutePath,
        "build", "--release", "-p", "sylva-android",
    )
    doLast {
        // The APK ships ARCore's library from the AAR; the Rust one sits beside it.
        check(File(out, "arm64-v8a/libsylva_android.so").exists()) { "cargo ndk did not build libsylva_android.so" }
    }
}

tasks.named("preBuild") { dependsOn(cargoNdk) }
