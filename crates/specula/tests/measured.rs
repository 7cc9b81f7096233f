use glam::DVec3;
use specula::measured::MeasuredBrdf;
#[test]
fn probe() {
    let b = MeasuredBrdf::from_bytes(&std::fs::read("/work/shared/data/rgl/paper_white_rgb.bsdf").unwrap()).unwrap();
    let v = DVec3::new(-0.22271355986595154, -0.9660465121269226, 0.13096894323825836);
    let l = DVec3::new(-0.8011023998260498, -0.5901339054107666, 0.0998842641711235);
    println!("{:?} {}", b.f_cos(v, l), b.pdf(v, l));
    for e in [1e-7, 1e-6, 1e-5] {
        for d in [DVec3::X, DVec3::Y, DVec3::Z] {
            let v2 = (v + e * d).normalize();
            let l2 = (l + e * d).normalize();
            println!("{e} v {:?} {} l {:?}", b.f_cos(v2, l).x / b.f_cos(v, l).x - 1.0, b.pdf(v2, l) / b.pdf(v, l) - 1.0, b.f_cos(v, l2).x / b.f_cos(v, l).x - 1.0);
        }
    }
}
