//! The checks of sensor settings: cameras, lidars, their quality.

use super::*;

#[test]
fn camera_settings() {
    let camera = |extra: &str| {
        with(
            "kind = \"depth_camera\"",
            &format!("kind = \"depth_camera\"\n{extra}"),
        )
    };
    assert_eq!(
        one(&camera("range_min = 6.0\nrange_max = 5.0")),
        finding(
            "uav[0].sensor[0].range_min",
            "must be below range_max (5.0)",
            "6.0"
        )
    );
    assert_eq!(
        one(&camera("range_min = -0.5")),
        finding("uav[0].sensor[0].range_min", "must be at least 0", "-0.5")
    );
    assert_eq!(
        one(&camera("range_max = -5.0")),
        finding("uav[0].sensor[0].range_max", "must be above 0", "-5.0")
    );
    assert_eq!(
        one(&camera("rate_hz = 0.0")),
        finding("uav[0].sensor[0].rate_hz", "must be above 0", "0.0")
    );
    assert_eq!(
        one(&camera("hfov = 3.2")),
        finding("uav[0].sensor[0].hfov", "must be in (0, pi) rad", "3.2")
    );
    assert_eq!(
        one(&camera("hfov = 0.0")),
        finding("uav[0].sensor[0].hfov", "must be in (0, pi) rad", "0.0")
    );
    assert_eq!(
        one(&camera("width = 0")),
        finding("uav[0].sensor[0].width", "must be at least 1", "0")
    );
    assert_eq!(
        one(&camera("ray_grid = [64, 0]")),
        finding("uav[0].sensor[0].ray_grid[1]", "must be at least 1", "0")
    );
    // A camera reaching no farther than its own 0.1 m voxel once ended "complete" at 0 %.
    assert_eq!(
        one(&camera("range_min = 0.0\nrange_max = 0.05")),
        finding(
            "uav[0].sensor[0].range_max",
            "must be above map.resolution (0.1 m): the sensor must reach past its own voxel",
            "0.05"
        )
    );
    // The default physics rate is 300 Hz; a faster camera was capped there silently.
    assert_eq!(
        one(&camera("rate_hz = 1e9")),
        finding(
            "uav[0].sensor[0].rate_hz",
            "must be at most physics_rate_hz (300.0): a sensor scans at most once per physics \
             step",
            "1000000000.0"
        )
    );
    assert_eq!(
        one(&camera("mount = { translation = [100.0, 0.0, 0.0] }")),
        finding(
            "uav[0].sensor[0].mount.translation",
            "must be within 2 m of the UAV's centre",
            "[100.0, 0.0, 0.0]"
        )
    );
    assert_eq!(
        findings(&camera("mount = { translation = [0.1, 0.0, -0.05] }")),
        vec![]
    );
    let (path, _, found) = one(&camera("ray_grid = [10000, 10000]"));
    assert_eq!(path, "uav[0].sensor[0].ray_grid");
    assert_eq!(found.as_deref(), Some("1.000e8 rays"));
    // Auto grid at 1 mm voxels and 50 m range: step 2e-5 rad; hfov 1.0 rad gives 50001
    // columns, vfov 2 atan(0.75 tan 0.5) = 0.77773 rad gives 38888 rows: 1.944e9 rays.
    let fine = with(
        "[world.bounds]",
        "[map]\nresolution = 0.001\n[world.bounds]",
    )
    .replace("max = [10.0, 10.0, 3.0]", "max = [1.0, 1.0, 1.0]")
    .replace("[1.0, 1.0, 1.0] }", "[0.5, 0.5, 0.5] }")
    .replace("[[5.0, 5.0, 1.0]]", "[[0.5, 0.6, 0.5]]")
    .replace(
        "kind = \"depth_camera\"",
        "kind = \"depth_camera\"\nrange_max = 50.0",
    );
    let (path, _, found) = one(&fine);
    assert_eq!(path, "uav[0].sensor[0].ray_grid");
    assert_eq!(found.as_deref(), Some("1.944e9 rays"));
}

#[test]
fn sensor_quality() {
    let camera = |extra: &str| {
        with(
            "kind = \"depth_camera\"",
            &format!("kind = \"depth_camera\"\n{extra}"),
        )
    };
    assert_eq!(
        one(&camera("quality = { p_hit = 0.4 }")),
        finding(
            "uav[0].sensor[0].quality.p_hit",
            "must be above 0.5 (a hit must raise the occupancy)",
            "0.4"
        )
    );
    assert_eq!(
        one(&camera("quality = { p_miss = 1.5 }")),
        finding(
            "uav[0].sensor[0].quality.p_miss",
            "must be a probability in (0, 1)",
            "1.5"
        )
    );
    assert_eq!(
        one(&camera("quality = { range_noise_std = -0.01 }")),
        finding(
            "uav[0].sensor[0].quality.range_noise_std",
            "must be at least 0",
            "-0.01"
        )
    );
    // The default camera reaches 5 m.
    assert_eq!(
        one(&camera("quality = { range_noise_std = 1e30 }")),
        finding(
            "uav[0].sensor[0].quality.range_noise_std",
            "must be below range_max (5.0 m)",
            "1e30"
        )
    );
    assert_eq!(
        findings(&camera("quality = { range_noise_std = 0.05 }")),
        vec![]
    );
}

#[test]
fn lidar_settings() {
    let lidar = |extra: &str| {
        with(
            "kind = \"depth_camera\"",
            &format!("kind = \"lidar\"\n{extra}"),
        )
    };
    assert_eq!(findings(&lidar("hfov = 6.283185307179586")), vec![]);
    assert_eq!(
        one(&lidar("hfov = 6.3")),
        finding("uav[0].sensor[0].hfov", "must be in (0, 2 pi] rad", "6.3")
    );
    assert_eq!(
        one(&lidar("beams_h = 0")),
        finding("uav[0].sensor[0].beams_h", "must be at least 1", "0")
    );
    assert_eq!(
        one(&lidar("vfov = 0.3")),
        finding(
            "uav[0].sensor[0].vfov",
            "must be 0 for a planar lidar (beams_v = 1); set beams_v for a multi-beam one",
            "0.3"
        )
    );
    assert_eq!(findings(&lidar("vfov = 0.5\nbeams_v = 16")), vec![]);
    assert_eq!(
        one(&lidar("vfov = 0.0\nbeams_v = 16")),
        finding("uav[0].sensor[0].vfov", "must be in (0, pi) rad", "0.0")
    );
    let (path, _, found) = one(&lidar("beams_h = 100000\nbeams_v = 1000\nvfov = 1.0"));
    assert_eq!(path, "uav[0].sensor[0].beams_h");
    assert_eq!(found.as_deref(), Some("1.000e8 rays"));
}
