//! A malformed CSV names its file, line and column; a missing column is named.

use std::path::Path;

use gaitclip_host::io::csv_trace::{parse, CsvError};

const HEADER: &str = "t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n";

#[test]
fn bad_number_names_file_line_and_column() {
    let text = format!("{HEADER}0,1,2,3,4,5,6\n0.005,1,2,abc,4,5,6\n");
    let e = parse(Path::new("walk.csv"), text.as_bytes()).unwrap_err();
    assert!(
        matches!(
            e,
            CsvError::BadNumber {
                line: 3,
                col: 4,
                ..
            }
        ),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        "walk.csv:3:4: column `acc_z`: `abc` is not a finite number"
    );
}

#[test]
fn non_finite_values_are_rejected() {
    let text = format!("{HEADER}0,1,2,3,NaN,5,6\n");
    let e = parse(Path::new("w.csv"), text.as_bytes()).unwrap_err();
    assert!(e.to_string().starts_with("w.csv:2:5:"), "{e}");
}

#[test]
fn missing_column_is_named() {
    let text = "t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y\n0,1,2,3,4,5\n";
    let e = parse(Path::new("w.csv"), text.as_bytes()).unwrap_err();
    assert!(e.to_string().contains("missing column `gyr_z`"), "{e}");
}

#[test]
fn short_row_names_its_line() {
    let text = format!("{HEADER}0,1,2,3,4,5,6\n0.005,1,2\n");
    let e = parse(Path::new("w.csv"), text.as_bytes()).unwrap_err();
    assert!(e.to_string().starts_with("w.csv:3:"), "{e}");
}

#[test]
fn columns_in_any_order_and_extra_columns_are_fine() {
    let text = "gyr_z,extra,t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y\n6,x,0.5,1,2,3,4,5\n";
    let s = parse(Path::new("w.csv"), text.as_bytes()).unwrap();
    assert_eq!(s[0].t_s, 0.5);
    assert_eq!(s[0].acc_mps2, [1.0, 2.0, 3.0]);
    assert_eq!(s[0].gyr_radps, [4.0, 5.0, 6.0]);
}

#[test]
fn header_only_is_empty() {
    let e = parse(Path::new("w.csv"), HEADER.as_bytes()).unwrap_err();
    assert_eq!(e.to_string(), "w.csv: no samples");
}

#[test]
fn time_going_back_names_line_and_column() {
    let text = "acc_x,t_s,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n1,0.010,2,3,4,5,6\n1,0.015,2,3,4,5,6\n1,0.020,2,3,4,5,6\n1,0.012,2,3,4,5,6\n";
    let e = parse(Path::new("w.csv"), text.as_bytes()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "w.csv:5:2: column `t_s`: 0.012 goes back from the previous sample's 0.02 by more than half a period"
    );
}

/// A stamp equal to the one before, or earlier by less than half a period, is a re-sent
/// sample: the first is kept, the repeat dropped.
#[test]
fn a_repeated_stamp_is_dropped_not_fatal() {
    let text = "t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n0.010,1,2,3,4,5,6\n0.015,1,2,3,4,5,6\n0.015,9,9,9,9,9,9\n0.0149,8,8,8,8,8,8\n0.020,1,2,3,4,5,6\n";
    let s = parse(Path::new("w.csv"), text.as_bytes()).unwrap();
    assert_eq!(
        s.iter().map(|s| s.t_s).collect::<Vec<_>>(),
        vec![0.010, 0.015, 0.020]
    );
    assert_eq!(
        s[1].acc_mps2,
        [1.0, 2.0, 3.0],
        "the first of the repeats is kept"
    );
}

/// Whitespace around a header's names and a row's cells is no part of them (ASCII and
/// Unicode alike, as csv's `Trim::All` read them); a bad padded cell is quoted trimmed, and a
/// missing column's header is listed trimmed.
#[test]
fn padded_names_and_cells_are_trimmed() {
    let text = " t_s ,\tacc_x, acc_y ,acc_z\u{a0},gyr_x , gyr_y,gyr_z\r\n 0.5 ,\t1, 2 ,3\u{a0},4 , 5,6\r\n";
    let s = parse(Path::new("w.csv"), text.as_bytes()).unwrap();
    assert_eq!(s[0].t_s, 0.5);
    assert_eq!(s[0].acc_mps2, [1.0, 2.0, 3.0]);
    assert_eq!(s[0].gyr_radps, [4.0, 5.0, 6.0]);
    let text = " t_s , acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n0, 1,2,  x y ,4,5,6\n";
    let e = parse(Path::new("w.csv"), text.as_bytes()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "w.csv:2:4: column `acc_z`: `x y` is not a finite number"
    );
    let text = " t_s , acc_x,acc_y,acc_z,gyr_x,gyr_y\n0,1,2,3,4,5\n";
    let e = parse(Path::new("w.csv"), text.as_bytes()).unwrap_err();
    assert!(
        e.to_string().contains("missing column `gyr_z`")
            && e.to_string().contains("t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y"),
        "{e}"
    );
}
