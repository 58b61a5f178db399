//! Results are bitwise identical for 1 and 2 threads: REV maps (summed-area table), Eq. (5),
//! gamma-spot removal and the synthetic forward model (blur, Poisson noise).

use lbdem_imaging::Roi;
use lbdem_imaging::beer_lambert::{FractionMap, eps_vol_field};
use lbdem_imaging::correct::remove_gamma_spots;
use lbdem_imaging::rev::Sat;
use lbdem_imaging::synth::{self, Beam, GrainShape};
use ndarray::Array2;

fn pipeline() -> Vec<Array2<f64>> {
    let disks = synth::pack_disks(Roi::new(0, 20, 300, 260), 24.0, 0.2, 0.45, 3).unwrap();
    let beam = Beam {
        i0: 30000.0,
        mu_s: 2147.85,
        mu_l: 10120.559,
    };
    let mut out = Vec::new();
    let mut raws = Vec::new();
    for (k, l) in [150e-6, 142.5e-6].into_iter().enumerate() {
        let (_, c) = synth::render(
            300,
            300,
            &disks,
            3,
            GrainShape::TruncatedSphere,
            25.0,
            l,
            &beam,
            &[],
            &[],
        );
        let b = synth::gaussian_blur(c.view(), 0.7);
        raws.push(synth::noisy_u16(b.view(), 5 + k as u64).unwrap());
    }
    let map = FractionMap::eq1(4000.0, 20000.0).unwrap();
    let mut sat = Sat::new();
    let mut revs = Vec::new();
    for r in &raws {
        sat.build_u16(r.view(), &map.lut_u16());
        revs.push(sat.rev_mean(75, 0.5).unwrap());
        let f = r.mapv(f64::from);
        out.push(remove_gamma_spots(f.view(), 3, 5.0).unwrap().0);
    }
    out.push(eps_vol_field(revs[0].view(), revs[1].view(), 0.1));
    out.extend(revs);
    out
}

#[test]
fn one_and_two_threads_give_identical_bits() {
    let run = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(pipeline)
    };
    let (a, b) = (run(1), run(2));
    for (x, y) in a.iter().zip(&b) {
        assert!(x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits()));
    }
}
