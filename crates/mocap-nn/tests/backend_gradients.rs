//! The CPU backend's gradients, checked against finite differences: the
//! stack was chosen because candle computed wrong conv1d weight gradients
//! for batches over one, and every learned capability trains through this
//! path (a spike detector that would not learn was traced here and found
//! fine, see bench/results/clean.md).

use mocap_nn::burn::module::Param;
use mocap_nn::burn::nn::conv::Conv1dConfig;
use mocap_nn::burn::nn::PaddingConfig1d;
use mocap_nn::burn::tensor::{Device, Tensor};

/// Conv1d weight gradients of burn's CPU backend against finite
/// differences (batch > 1, several channels, `Same` padding).
#[test]
fn conv_weight_gradients_match_finite_differences() {
    let device = Device::flex().autodiff();
    let (b, cin, cout, t, k) = (3, 4, 5, 9, 3);
    let data = |n: usize, seed: f32| -> Vec<f32> {
        (0..n)
            .map(|i| (i as f32 * 0.7 + seed).sin() * 1.3)
            .collect()
    };
    let x =
        Tensor::<1>::from_floats(data(b * cin * t, 0.1).as_slice(), &device).reshape([b, cin, t]);
    let target =
        Tensor::<1>::from_floats(data(b * cout * t, 2.0).as_slice(), &device).reshape([b, cout, t]);
    let w0 = data(cout * cin * k, 5.0);
    let loss_of = |w: &[f32], grad: bool| {
        let mut conv = Conv1dConfig::new(cin, cout, k)
            .with_padding(PaddingConfig1d::Same)
            .with_bias(false)
            .init(&device);
        let wt = Tensor::<1>::from_floats(w, &device).reshape([cout, cin, k]);
        conv.weight = Param::from_tensor(if grad { wt.require_grad() } else { wt });
        let y = conv.forward(x.clone());
        let loss = (y - target.clone()).powi_scalar(2).mean();
        (conv, loss)
    };
    let (conv, loss) = loss_of(&w0, true);
    let grads = loss.backward();
    let g: Vec<f32> = conv
        .weight
        .val()
        .grad(&grads)
        .unwrap()
        .into_data()
        .try_to_vec()
        .unwrap();
    for i in [0, 7, 13, 31, 59] {
        let h = 1e-2;
        let mut wp = w0.clone();
        wp[i] += h;
        let mut wm = w0.clone();
        wm[i] -= h;
        let lp: f32 = loss_of(&wp, false).1.into_scalar();
        let lm: f32 = loss_of(&wm, false).1.into_scalar();
        let numeric = (lp - lm) / (2.0 * h);
        assert!(
            (g[i] - numeric).abs() < 1e-3 * (1.0 + numeric.abs()),
            "weight {i}: autodiff {} numeric {numeric}",
            g[i]
        );
    }
}
