//! Elastic impact energy with filter/hourglass and the disc switched:
//! `cargo run --release --example impact2 -- N FILTER_EVERY HOURGLASS [RADIUS_M SPEED_M_S DENSITY [shepard|mls]]`.
use grit_sph::verification::elastic_impact::{simulate_with, Disc};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let arg = |k: usize| a.get(k).map(|x| x.parse::<f64>().expect("a number"));
    let n = arg(1).expect("N") as usize;
    let s = grit_sph::Settings {
        shepard_interval: arg(2).expect("FILTER_EVERY") as u32,
        hourglass: arg(3).expect("HOURGLASS"),
        density_filter: match a.get(7).map(String::as_str) {
            Some("mls") => grit_sph::DensityFilter::Mls,
            _ => grit_sph::DensityFilter::Shepard,
        },
        ..Default::default()
    };
    let d = Disc::default();
    let disc = Disc {
        radius_m: arg(4).unwrap_or(d.radius_m),
        speed_m_s: arg(5).unwrap_or(d.speed_m_s),
        density_kg_m3: arg(6).unwrap_or(d.density_kg_m3),
    };
    let t0 = std::time::Instant::now();
    let h = match simulate_with(n, s, disc, None) {
        Ok(h) => h,
        Err(e) => {
            println!("{e}");
            return;
        }
    };
    println!(
        "peak {:.4} at release {:.4} end {:.4} filter {:.4} hourglass {:.4} damping {:.4} steps {} wall {:.1} s",
        h.peak,
        h.at_release,
        h.energy.last().unwrap(),
        h.work.density_filter,
        h.work.hourglass,
        h.work.contact_damping,
        h.t.len() * 10,
        t0.elapsed().as_secs_f64()
    );
}
