//! The explorer's volume view: a volume ray marched with a chosen lobe, shaded as
//! `specula volume --mode dvr` shades it (with the volume's default transfer function).
//!
//! The volumes are the built-in ones, each made on a grid small enough to ray march at
//! interactive rates on a laptop's cores (the Shepp-Logan head at 64^3, the Marschner-Lobb
//! signal on its classic 41^3 grid), and the real scans Debian ships, offered only while their
//! files are installed ([`Choice::available`]): `ct-head`, InVesalius' `Cranium.inv3` (a head
//! CT, 256 x 256 x 108, int16 Hounsfield units, so drawn with `ct-bone`), and `mri-head`,
//! MRIcron's `ch2.nii.gz` (the Colin27 T1 with skull, 181 x 217 x 181, drawn with `mr`).
//!
//! Each volume is read or made once, at its first request, and kept with its prepared form
//! (gradients and bricks, what every frame marches through) and its transfer function: a scan
//! takes about half a second to read and prepare, then only its frames cost. A failed read
//! is not kept, so the next request tries again.

use std::path::Path;
use std::sync::{Mutex, OnceLock, PoisonError};

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::Display;
use specula_volume::dvr::{render_dvr_prepared, DvrSettings, Shading, View};
use specula_volume::march::PreparedVolume;
use specula_volume::phantom::BuiltIn;
use specula_volume::transfer::TransferFunction;
use specula_volume::Volume;

/// The largest volume render side, in pixels.
pub const MAX_VOLUME_SIZE: u32 = 512;

/// A real scan the explorer offers when its file is installed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scan {
    /// Debian's `invesalius-examples`: a head CT as an InVesalius project.
    CtHead,
    /// Debian's `mricron-data`: the Colin27 T1 MRI with skull, as NIfTI.
    MriHead,
}

impl Scan {
    /// Every scan, in the order the explorer lists them.
    pub const ALL: [Scan; 2] = [Scan::CtHead, Scan::MriHead];

    /// Its name in the explorer and the API.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Scan::CtHead => "ct-head",
            Scan::MriHead => "mri-head",
        }
    }

    /// Where Debian installs it.
    #[must_use]
    pub fn path(self) -> &'static Path {
        Path::new(match self {
            Scan::CtHead => "/usr/share/doc/invesalius-examples/examples/Cranium.inv3",
            Scan::MriHead => "/usr/share/mricron/templates/ch2.nii.gz",
        })
    }

    /// The Debian package that installs it.
    #[must_use]
    pub fn package(self) -> &'static str {
        match self {
            Scan::CtHead => "invesalius-examples",
            Scan::MriHead => "mricron-data",
        }
    }

    /// Whether its file is there.
    #[must_use]
    pub fn installed(self) -> bool {
        self.path().is_file()
    }
}

/// A volume the view can show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// Made by the library.
    BuiltIn(BuiltIn),
    /// Read from an installed file.
    Scan(Scan),
}

impl Choice {
    /// Its name in the explorer and the API.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Choice::BuiltIn(volume) => volume.id(),
            Choice::Scan(scan) => scan.id(),
        }
    }

    /// The built-in volumes, then the scans whose files are installed now.
    #[must_use]
    pub fn available() -> Vec<Choice> {
        BuiltIn::ALL
            .into_iter()
            .map(Choice::BuiltIn)
            .chain(
                Scan::ALL
                    .into_iter()
                    .filter(|scan| scan.installed())
                    .map(Choice::Scan),
            )
            .collect()
    }

    /// Its place among the cached volumes.
    fn slot(self) -> usize {
        match self {
            Choice::BuiltIn(volume) => volume as usize,
            Choice::Scan(scan) => BuiltIn::ALL.len() + scan as usize,
        }
    }
}

/// The explorer's grid side of a built-in volume.
fn side(volume: BuiltIn) -> usize {
    match volume {
        BuiltIn::SheppLogan => 64,
        BuiltIn::MarschnerLobb => 41,
    }
}

/// A volume ready to render.
struct Loaded {
    volume: Volume,
    prepared: PreparedVolume,
    /// Its default transfer function, in its values.
    transfer: TransferFunction,
}

fn load(choice: Choice) -> Result<Loaded, String> {
    let (volume, transfer) = match choice {
        Choice::BuiltIn(built_in) => (
            built_in.make(side(built_in)).map_err(|e| e.to_string())?,
            built_in.transfer(),
        ),
        Choice::Scan(scan) => {
            let volume = specula_volume::read(scan.path()).map_err(|e| e.to_string())?;
            // `ct-bone` for Hounsfield units (the CT), `mr` otherwise.
            let transfer = TransferFunction::default_for(&volume);
            (volume, transfer)
        }
    };
    Ok(Loaded {
        prepared: PreparedVolume::new(&volume),
        transfer: transfer.for_volume(&volume),
        volume,
    })
}

/// The volume, read or made at its first request and kept (a failure is not kept).
fn loaded(choice: Choice) -> Result<&'static Loaded, String> {
    const SLOTS: usize = BuiltIn::ALL.len() + Scan::ALL.len();
    static CACHE: [OnceLock<Loaded>; SLOTS] = [const { OnceLock::new() }; SLOTS];
    // One load at a time: concurrent first requests wait for it rather than read twice.
    static LOADING: Mutex<()> = Mutex::new(());
    let cell = &CACHE[choice.slot()];
    if let Some(loaded) = cell.get() {
        return Ok(loaded);
    }
    let _turn = LOADING.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(loaded) = cell.get() {
        return Ok(loaded);
    }
    let fresh = load(choice)?;
    Ok(cell.get_or_init(|| fresh))
}

/// One volume render.
#[derive(Clone, Copy, Debug)]
pub struct VolumeRequest {
    pub volume: Choice,
    pub view: View,
    pub kind: LobeKind,
    pub n: Exponent,
    pub geometry: Geometry,
    pub normalisation: Normalisation,
    pub size: u32,
}

/// The render as an sRGB PNG.
pub fn volume_png(request: &VolumeRequest) -> Result<Vec<u8>, String> {
    let Loaded {
        volume,
        prepared,
        transfer,
    } = loaded(request.volume)?;
    let shading = Shading::new(
        Lobe::new(request.kind, request.n),
        request.geometry,
        request.normalisation,
    );
    let settings = DvrSettings::new(request.size, request.size, request.view, Some(shading));
    let image = render_dvr_prepared(volume, prepared, transfer, &settings, &|| {})
        .map_err(|e| e.to_string())?;
    let display = Display::default();
    specula_render::encode_png_srgb8(image.width(), image.height(), &image.to_srgb8(display))
        .map_err(|e| e.to_string())
}
