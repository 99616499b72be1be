mod common;
use obbtree::build::{build, BuildOptions};
use obbtree::bv::BvKind;
use obbtree::fit::FitMethod;
use obbtree::real::Precision;

#[test]
fn smoke() {
    let mesh = common::uv_sphere(1.0, 20, 40);
    for bv in BvKind::ALL {
        for precision in Precision::ALL {
            for leaf_size in [1, 4] {
                let opts = BuildOptions {
                    bv,
                    precision,
                    fit: FitMethod::Hull,
                    leaf_size,
                };
                let f = build(&mesh, &opts, None).unwrap();
                f.verify().unwrap();
                println!("{:?}", f.info());
            }
        }
    }
}
