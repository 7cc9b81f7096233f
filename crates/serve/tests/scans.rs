//! The volume view's real scans, through the router: listed by `/api/models` exactly when
//! their files are installed, refused by name otherwise, and rendered as the library renders
//! them with their default transfer functions.
//!
//! A test binary of its own (its own process): the scans are kept in memory once read (a few
//! hundred MiB with their prepared gradients), which would otherwise count against the unit
//! tests' bound on the server's resident memory.
//!
//! The scans come from Debian's `invesalius-examples` and `mricron-data`. Without them a run
//! prints `skipped: ...`, except under `CI=true`, where `.ci/run` installs both and a missing
//! one is a failure.

use axum::body::{to_bytes, Body};
use axum::http::{Request, StatusCode};
use serde_json::Value;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_serve::{router, Scan};
use specula_volume::dvr::{render_dvr, DvrSettings, Shading, View};
use specula_volume::transfer::TransferFunction;
use specula_volume::{self as volume, Units};
use tower::ServiceExt as _;

async fn get(uri: &str) -> (StatusCode, Vec<u8>) {
    let response = router()
        .oneshot(Request::get(uri).body(Body::empty()).expect("request"))
        .await
        .expect("infallible");
    let status = response.status();
    let body = to_bytes(response.into_body(), usize::MAX)
        .await
        .expect("body");
    (status, body.to_vec())
}

async fn json(uri: &str) -> (StatusCode, Value) {
    let (status, body) = get(uri).await;
    (status, serde_json::from_slice(&body).expect("JSON body"))
}

/// Whether `scan` is installed; under `CI=true` it must be.
fn installed(scan: Scan) -> bool {
    if scan.installed() {
        return true;
    }
    assert!(
        std::env::var("CI").as_deref() != Ok("true"),
        "{} is missing, and CI=true requires it: apt-get install {}",
        scan.path().display(),
        scan.package()
    );
    eprintln!(
        "skipped: {} is missing (apt-get install {})",
        scan.path().display(),
        scan.package()
    );
    false
}

#[tokio::test]
async fn the_registry_lists_the_real_scans_when_installed() {
    let (status, models) = json("/api/models").await;
    assert_eq!(status, StatusCode::OK);
    let listed: Vec<&str> = models["volumes"]
        .as_array()
        .expect("volumes")
        .iter()
        .map(|v| v.as_str().expect("a name"))
        .collect();
    let mut expected = vec!["phantom", "marschner-lobb"];
    for scan in Scan::ALL {
        if installed(scan) {
            expected.push(scan.id());
        }
    }
    assert_eq!(listed, expected);

    // An unknown volume is refused with the choices there are.
    let (status, refusal) = json("/api/volume?volume=brain").await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert_eq!(refusal["parameter"], "volume");
    assert_eq!(refusal["error"], "unknown volume `brain`");
    assert_eq!(refusal["valid"], expected.join(", "));
}

/// The PNG's width and height, from its IHDR chunk.
fn png_size(png: &[u8]) -> (u32, u32) {
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let word = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().expect("4 bytes"));
    (word(16), word(20))
}

/// `scan` seen from the front: the served PNG is `size` square, byte for byte the library's
/// ray marcher on the file as read, with `preset` (its default transfer function) and the
/// address's lobe; and its centre is the head, not the black background.
async fn renders_from_the_front(scan: Scan, units: Units, preset: &str) {
    if !installed(scan) {
        return;
    }
    const SIZE: u32 = 64;
    let uri = format!(
        "/api/volume?volume={}&view=anterior&lobe=pow&n=40&geometry=blinn&normalisation=thesis-phon\
            g&size={SIZE}",
        scan.id()
    );
    let (status, served) = get(&uri).await;
    assert_eq!(
        status,
        StatusCode::OK,
        "{uri}: {}",
        String::from_utf8_lossy(&served)
    );
    assert_eq!(png_size(&served), (SIZE, SIZE), "{uri}");

    let volume = volume::read(scan.path()).expect("the scan reads");
    assert_eq!(volume.units(), units, "{}", scan.id());
    let transfer = TransferFunction::preset(preset)
        .expect("a preset")
        .for_volume(&volume);
    let shading = Shading::new(
        Lobe::new(LobeKind::Pow, Exponent::new(40.0)),
        Geometry::Blinn,
        Normalisation::ThesisPhong,
    );
    let settings = DvrSettings::new(SIZE, SIZE, View::Anterior, Some(shading));
    let image = render_dvr(&volume, &transfer, &settings, &|| {}).expect("render");
    let direct = specula_render::encode_png_srgb8(SIZE, SIZE, &image.to_srgb8(Default::default()))
        .expect("png");
    assert!(
        served == direct,
        "{}: the served image is not the library's render with {preset}",
        scan.id()
    );

    // The 8 x 8 pixels at the centre: the head, lit, against the black background.
    let centre = SIZE as usize / 2;
    let mean = (centre - 4..centre + 4)
        .flat_map(|y| (centre - 4..centre + 4).map(move |x| (x, y)))
        .map(|(x, y)| image.pixels()[y * SIZE as usize + x].max_element())
        .sum::<f32>()
        / 64.0;
    assert!(
        mean > 0.05,
        "{}: the centre is background ({mean})",
        scan.id()
    );
}

#[tokio::test]
async fn ct_head_is_drawn_as_ct_in_hounsfield_units() {
    renders_from_the_front(Scan::CtHead, Units::Hounsfield, "ct-bone").await;
}

#[tokio::test]
async fn mri_head_is_drawn_with_the_mr_function() {
    renders_from_the_front(Scan::MriHead, Units::Arbitrary, "mr").await;
}
