package org.sylva.app

import android.Manifest
import android.app.NativeActivity
import android.content.pm.PackageManager
import android.os.Bundle

/**
 * The NativeActivity that runs libsylva_android.so (android_main). It only asks for the camera
 * at run time: the Rust side creates the ARCore session at the next resume once it is granted
 * (the permission dialog pauses and resumes the activity). Rotation is handled in place
 * (configChanges in the manifest): the native window is resized, the design stays.
 */
class MainActivity : NativeActivity() {
    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        if (checkSelfPermission(Manifest.permission.CAMERA) != PackageManager.PERMISSION_GRANTED) {
            requestPermissions(arrayOf(Manifest.permission.CAMERA), CAMERA_REQUEST)
        }
    }

    private companion object {
        const val CAMERA_REQUEST = 1
    }
}
